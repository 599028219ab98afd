//! Specimen description → full `ceiling-fe-model`: the `[structure]` table of
//! the measured-data bundle and the `[model]` variant choices ([`spec`]), the
//! 15 calibration parameters of seed Table 6.1 and the variants' extension
//! parameters with their units and priors ([`params`]), and the builders:
//! grid ([`grid`]), hanger rods ([`rods`]), perimeter ([`perimeter`]) with
//! each grid line's support along its axis ([`along`]), grid connections
//! ([`connections`]).
//!
//! ```no_run
//! let spec = fe::generator::CeilingSpec::from_toml_file(std::path::Path::new("configs/specimens/type-c.toml")).unwrap();
//! let model = fe::generator::generate(&spec, &fe::generator::Parameters::prior_midpoints_for(&spec)).unwrap();
//! ```

pub mod along;
pub mod connections;
pub mod grid;
pub mod params;
pub mod perimeter;
pub mod rods;
pub mod spec;

pub use grid::{along_factor_names, generate, GenerateError};
pub use params::{
    param_info, parameters_for, Domain, ParamError, ParamInfo, Parameters, EXTENSIONS, LINEAR_FORM,
    MEMBER_KG_PER_M, PARAMETERS,
};
pub use spec::{
    Boundary, CeilingSpec, Connections, EndCondition, ModelOptions, Perimeter, SpecError,
    Structure, Variant,
};
