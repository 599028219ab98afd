//! The coordinator: reads a study, draws its design, runs it on a farm of
//! workers through a transport, keeps every result in a crash-safe store,
//! and runs the analyses centrally.
