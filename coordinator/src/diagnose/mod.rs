//! Diagnosis of a measured-data bundle: the evidence (symptoms) that tells
//! where and how a simulation departs from shaking-table measurements.
//!
//! Every kernel here works on plain sample slices (SI units, uniform step
//! `dt_s`) so that measured and simulated runs are judged by the same code.

pub mod band_likelihood;
pub mod calibrate;
pub mod campaign;
pub mod campaign_size;
pub mod cause;
pub mod channel_start;
pub mod class_evidence;
pub mod class_odds;
pub mod class_search;
pub mod damping_form;
pub mod damping_path;
pub mod damping_share;
pub mod effect;
pub mod ensemble;
pub mod envelope;
pub mod evidence;
pub mod executor;
pub mod farm_executor;
pub mod filter;
pub mod fit;
pub mod joined_start;
pub mod levenberg;
pub mod likelihood;
pub mod linear_part;
pub mod linear_stage;
pub mod loop_damping;
pub mod mdl;
pub mod modal_fit;
pub mod noise_floor;
pub mod pipeline;
pub mod posterior;
pub mod posterior_check;
pub mod reach;
pub mod refine;
pub mod report;
pub mod report_evidence;
pub mod report_linear;
pub mod report_posterior;
pub mod report_symptoms;
pub mod resample;
pub mod resume;
pub mod ridge;
pub mod spectrogram;
pub mod spectrum;
pub mod stage_load;
pub mod symptoms;
pub mod unexplained;
pub mod verdict;
pub mod verdict_notes;

#[cfg(test)]
pub(crate) mod testkit;

#[cfg(test)]
pub(crate) mod farm_executor_tests;
#[cfg(test)]
mod fit_tests;
#[cfg(test)]
mod shared_form_tests;
