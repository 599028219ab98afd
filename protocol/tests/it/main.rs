//! The integration tests of ceilfarm-protocol in one test binary, so that
//! the crate and its transports (zenoh, iceoryx2) are linked once: one
//! module per subject. One module alone: `cargo test -p ceilfarm-protocol
//! --test it MODULE::`.

mod decode_limits;
mod security_decoder_fuzz;
mod zenoh_refusals;
