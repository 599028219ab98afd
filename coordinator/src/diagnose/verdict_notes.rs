//! The verdict's warnings and notes: when the runs the diagnosis was not
//! calibrated on do not confirm its cause, cannot measure it, contradict
//! the baseline, or drive the specimen far beyond the calibration runs.

use super::cause::Cause;
use super::pipeline::Diagnosis;
use super::reach::validation_reach;
use super::report::num;
use crate::bundle::Bundle;
use crate::report::{Block, NoteKind};

/// Gain below which a named extension and the baseline are said to
/// predict the validation runs alike.
pub const ALIKE_GAIN: f64 = 0.1;
/// The named extension's calibration error over the baseline's (both in
/// excess of the noise) below which it is said to fit the calibration runs
/// far better.
pub const FAR_BETTER: f64 = 0.5;

/// A warning when the named extension fits the calibration runs far better
/// than the baseline but both predict the validation runs alike: the
/// validation runs barely exercise the physics (a white-noise run in xy
/// closed the gaps in y, the validation sweep in x barely reaches them),
/// so the gain cannot measure the extension.
pub fn unexercised_note(d: &Diagnosis) -> Option<Block> {
    let base = d.candidates.iter().find(|c| c.cause == Cause::NONE)?;
    let named = d.candidates.iter().find(|c| c.cause == d.cause && c.cause != Cause::NONE)?;
    let (bc, nc) = (base.calibration_excess_error, named.calibration_excess_error);
    let (bv, nv) = (d.baseline_validation_error, d.extended_validation_error);
    let alike = nv <= bv && d.gain < ALIKE_GAIN;
    let better = nc < FAR_BETTER * bc;
    let finite = [bc, nc, bv, nv].iter().all(|v| v.is_finite());
    (finite && alike && better).then(|| Block::Note {
        kind: NoteKind::Warning,
        text: format!(
            "{} fits the calibration runs far better than the baseline (error {} against {}, \
             in excess of the noise), but the two predict the validation runs alike (validation \
             error {} against {}, gain {:.3}): the validation runs barely exercise what it adds, \
             so the gain does not measure it. Validating on runs that drive the specimen as far \
             as the calibration runs that show it (the same direction, at least the same \
             amplitude) would.",
            d.cause.as_str(),
            num(nc),
            num(bc),
            num(nv),
            num(bv),
            d.gain
        ),
    })
}

/// With no extension chosen, the baseline's validation error over its
/// calibration error (both in excess of the noise) above which the report
/// says the validation runs show a response the calibration runs do not.
pub const UNEXPLAINED_RATIO: f64 = 3.0;
/// The baseline validation error that must be exceeded as well: a miss of
/// a few percent is within what null campaigns show.
pub const UNEXPLAINED_FLOOR: f64 = 0.03;

/// A warning when no extension is chosen but the baseline misses the
/// validation runs far more than the calibration runs: `none` is the
/// verdict of the calibration runs, and the validation runs contradict it.
pub fn unexplained_note(d: &Diagnosis) -> Option<Block> {
    let base = d.candidates.iter().find(|c| c.cause == Cause::NONE)?;
    let (val, cal) = (base.validation_error, base.calibration_excess_error);
    let far = val > UNEXPLAINED_FLOOR && val > UNEXPLAINED_RATIO * cal.max(0.0);
    (d.cause == Cause::NONE && val.is_finite() && cal.is_finite() && far).then(|| Block::Note {
        kind: NoteKind::Warning,
        text: format!(
            "No extension earns its complexity on the calibration runs, yet the baseline \
             misses the validation runs by {} in excess of the noise, against {} on the \
             calibration runs: the validation runs show a response the calibration runs do \
             not, and the baseline does not explain them within their noise. Physics that \
             acts only above the calibration runs' amplitude (a gap that closes, a slip force \
             that is reached) cannot be calibrated on them; the symptoms of the validation \
             runs below say what it looks like, and calibrating on runs that reach it would \
             name it.",
            num(val),
            num(cal)
        ),
    })
}

/// Validation peak over calibration peak above which the report says the
/// validation runs go beyond the calibration runs: twice, not merely the
/// stronger shaking a campaign usually validates on (sweeps 0.1 g stronger
/// than the calibration ones reach 1.2 to 1.5 times without any effect).
pub const REACH_NOTE: f64 = 2.0;

/// A note when the validation runs drive the specimen well beyond the
/// calibration runs ([`validation_reach`]).
pub fn reach_note(b: &Bundle, d: &Diagnosis) -> Option<Block> {
    let r = validation_reach(b, &d.calibration_runs, &d.validation_runs)?;
    (r.ratio > REACH_NOTE).then(|| Block::Note {
        kind: NoteKind::Info,
        text: format!(
            "The validation runs drive the specimen far beyond the calibration runs: sensor {}'s \
             peak in them is {:.2} times its largest in the calibration runs. Physics that acts \
             only above the calibration runs' amplitude (a gap that closes, a slip force that \
             is reached) cannot be calibrated on them; the gain measures how well each model \
             extrapolates.",
            r.sensor, r.ratio
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::testkit::pounding_diagnosis;

    fn warning_text(b: Option<Block>) -> Option<String> {
        b.map(|b| match b {
            Block::Note { kind: NoteKind::Warning, text } => text,
            other => panic!("not a warning: {other:?}"),
        })
    }

    #[test]
    fn an_extension_the_validation_runs_barely_exercise_is_flagged() {
        let (_, mut d) = pounding_diagnosis(true, true);
        let set = |d: &mut Diagnosis, cause: Cause, cal: f64| {
            let c = d.candidates.iter_mut().find(|c| c.cause == cause).unwrap();
            c.calibration_excess_error = cal;
        };
        set(&mut d, Cause::NONE, 0.246);
        set(&mut d, Cause::PERIMETER_POUNDING, 0.043);
        (d.baseline_validation_error, d.extended_validation_error) = (0.0293, 0.0291);
        d.gain = 1.0 - 0.0291 / 0.0293;
        let text = warning_text(unexercised_note(&d)).expect("an unexercised extension");
        assert!(text.contains("0.0430") && text.contains("0.246") && text.contains("0.0291"));
        // A real gain, a calibration fit not far better, a worse prediction,
        // or the baseline named: no note.
        d.extended_validation_error = 0.01;
        d.gain = 1.0 - 0.01 / 0.0293;
        assert_eq!(warning_text(unexercised_note(&d)), None, "a gain of 0.66");
        (d.extended_validation_error, d.gain) = (0.0291, 0.007);
        set(&mut d, Cause::PERIMETER_POUNDING, 0.2);
        assert_eq!(warning_text(unexercised_note(&d)), None, "0.2 against 0.246");
        set(&mut d, Cause::PERIMETER_POUNDING, 0.043);
        (d.extended_validation_error, d.gain) = (0.0300, -0.024);
        assert_eq!(warning_text(unexercised_note(&d)), None, "a worse prediction");
        d.cause = Cause::NONE;
        assert_eq!(warning_text(unexercised_note(&d)), None, "the baseline named");
    }

    #[test]
    fn a_baseline_the_validation_runs_contradict_is_flagged() {
        let (_, mut d) = pounding_diagnosis(true, true);
        d.cause = Cause::NONE;
        let set = |d: &mut Diagnosis, cal: f64, val: f64| {
            let base = d.candidates.iter_mut().find(|c| c.cause == Cause::NONE).unwrap();
            (base.calibration_excess_error, base.validation_error) = (cal, val);
        };
        set(&mut d, 0.01, 0.097);
        let text = warning_text(unexplained_note(&d)).expect("a contradicted baseline");
        assert!(text.contains("0.0970") && text.contains("0.0100"), "{text}");
        // Within the floor, within the ratio, or an extension named: no note.
        set(&mut d, 0.001, 0.025);
        assert_eq!(warning_text(unexplained_note(&d)), None, "below the floor");
        set(&mut d, 0.02, 0.05);
        assert_eq!(warning_text(unexplained_note(&d)), None, "2.5 times");
        set(&mut d, f64::NAN, 0.2);
        assert_eq!(warning_text(unexplained_note(&d)), None, "no calibration error");
        set(&mut d, 0.01, 0.097);
        d.cause = Cause::PERIMETER_POUNDING;
        assert_eq!(warning_text(unexplained_note(&d)), None, "an extension named");
    }
}
