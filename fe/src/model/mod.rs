//! The neutral model `ceiling-fe-model` v1 (units N, mm, s, t): the types
//! ([`ir`]), reading and writing JSON ([`json`]) and the checks run on load
//! ([`validate`]).
//!
//! ```no_run
//! let model = fe::model::read_model(std::path::Path::new("model.json")).unwrap();
//! println!("{} nodes", model.nodes.len());
//! ```

pub mod ir;
pub mod json;
pub mod validate;

pub use ir::{
    Analysis, Beam, Damping, DampingStiffness, Fixity, Mass, MaterialDef, Model, Node, Spring,
    Units, FORMAT_NAME, FORMAT_VERSION,
};
pub use json::{parse_model, read_model, write_model, ReadError};
pub use validate::{validate, ModelError};
