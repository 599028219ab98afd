//! Under the evidence's verdict every class carries the baseline's linear
//! form: on the tiny campaign (pounding hidden) damped at 8 %
//! mass-proportionally (the damping's share on the mass term 1, where every
//! variant is damped by the even Rayleigh pair), the baseline's mass-share
//! twin wins (by 494 nats, the share found at 1.0), and then every class,
//! the class of pounding with friction included, calibrates the share.

use super::executor::ThreadExecutor;
use super::farm_executor_tests::{tiny_options, TINY};
use super::fit::DAMPING_MASS_SHARE;
use super::pipeline::{diagnose_with, Diagnosis};
use crate::bundle::read_bundle;

/// The tiny campaign damped at 8 % on the mass term alone, diagnosed under
/// the evidence's verdict ([`tiny_options`]).
fn diagnosed() -> Diagnosis {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("campaign.toml");
    let damped =
        TINY.replace("damping_ratio = 0.04", "damping_ratio = 0.08\ndamping_mass_share = 1.0");
    assert_ne!(damped, TINY, "the fixture's damping line moved");
    std::fs::write(&spec, damped).unwrap();
    let out = dir.path().join("bundle");
    crate::synth::synth_to_dir(&spec, &out, &dir.path().join("answer.json"), &mut |_| {}).unwrap();
    let b = read_bundle(&out).unwrap();
    diagnose_with(&b, &tiny_options(), &mut ThreadExecutor::new(2), &mut |_, _, _| {}).unwrap()
}

/// Whether candidate `k` calibrates the mass share.
fn frees_share(d: &Diagnosis, k: usize) -> bool {
    d.candidates[k].estimates.iter().any(|e| e.name == DAMPING_MASS_SHARE)
}

#[test]
fn every_class_carries_the_baselines_mass_share() {
    let d = diagnosed();
    let classes: Vec<(&str, bool)> = (0..d.candidates.len())
        .map(|k| (d.candidates[k].cause.as_str(), frees_share(&d, k)))
        .collect();
    eprintln!("{classes:?}");
    assert!(frees_share(&d, 0), "the baseline's twin should win: {classes:?}");
    assert!(d.candidates.iter().any(|c| c.cause.effects().count() > 1), "{classes:?}");
    assert!(classes.iter().all(|(_, share)| *share), "{classes:?}");
}
