//! The protocol crate's integration tests, one module per subject.

mod security_decoder_fuzz;
