//! The integration tests of ceilfarm-fe in one test binary, so that the crate
//! and its dependencies are linked once: one module per subject, and
//! `common` for the helpers they share (the verification folder, CSV rows,
//! MAC). One module alone: `cargo test -p ceilfarm-fe --test it MODULE::`.

mod ceiling_simulate;
mod common;
mod generator_along;
mod generator_boundaries;
mod generator_linear_form;
mod generator_rods;
mod generator_type_c;
mod generator_variants;
mod generator_wall_members;
mod materials_driver;
mod materials_fixtures;
mod materials_opensees_extra;
mod materials_props;
mod materials_speed;
mod modal_opensees;
mod modal_properties;
mod modal_response;
mod model_validation;
mod transient_committed_damping;
mod transient_failure;
mod transient_newton_variants;
mod transient_opensees;
mod transient_round_off;
mod transient_snapback;
mod transient_stages;
