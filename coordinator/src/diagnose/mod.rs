//! Diagnosis of a measured-data bundle: the evidence (symptoms) that tells
//! where and how a simulation departs from shaking-table measurements.
//!
//! Every kernel here works on plain sample slices (SI units, uniform step
//! `dt_s`) so that measured and simulated runs are judged by the same code.

pub mod filter;
pub mod spectrum;
pub mod symptoms;

#[cfg(test)]
mod testkit;
