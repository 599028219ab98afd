//! Specimen description → full `ceiling-fe-model`: the `[structure]` table of
//! the measured-data bundle ([`spec`]), the 15 calibration parameters of seed
//! Table 6.1 with their units ([`params`]), and the grid builder ([`grid`]).
//!
//! ```no_run
//! let spec = fe::generator::CeilingSpec::from_toml_file(std::path::Path::new("configs/specimens/type-c.toml")).unwrap();
//! let model = fe::generator::generate(&spec, &fe::generator::Parameters::prior_midpoints()).unwrap();
//! ```

pub mod grid;
pub mod params;
pub mod spec;

pub use grid::{generate, GenerateError};
pub use params::{ParamError, Parameters, PARAMETERS};
pub use spec::{Boundary, CeilingSpec, SpecError, Variant};
