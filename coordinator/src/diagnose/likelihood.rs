//! Which likelihood scores a point's channel fits: the time-domain Gaussian
//! under fixed channel weights (what the calibration's searches minimise)
//! or the band likelihood ([`super::band_likelihood`], whose nats do not
//! grow with the sampling rate). Both add the identified frequencies' term
//! ([`super::modal_fit`]) where a point has it.

use super::band_likelihood::BandFit;
use super::fit::{neg_log_lik, ChannelFit};

/// A likelihood of channel fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Likelihood<'a> {
    /// Profiled Gaussian in time, channel c counting `n_eff[c]` independent
    /// samples ([`super::fit::neg_log_lik`]).
    Time(&'a [f64]),
    /// Whittle over the model's band, the level profiled per sub-band
    /// ([`super::band_likelihood::model_band_fit`]); channels without bins
    /// in the band do not count.
    Band,
}

/// The kind of likelihood a policy asks for (the weights are the
/// diagnosis's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LikelihoodKind {
    /// [`Likelihood::Time`].
    Time,
    /// [`Likelihood::Band`].
    #[default]
    Band,
}

impl LikelihoodKind {
    /// This kind with the diagnosis's channel weights `n_eff`.
    pub fn with<'a>(self, n_eff: &'a [f64]) -> Likelihood<'a> {
        match self {
            LikelihoodKind::Time => Likelihood::Time(n_eff),
            LikelihoodKind::Band => Likelihood::Band,
        }
    }

    /// Its name in `diagnosis.json` and the report.
    pub fn as_str(self) -> &'static str {
        match self {
            LikelihoodKind::Time => "time",
            LikelihoodKind::Band => "band",
        }
    }
}

impl Likelihood<'_> {
    /// −ln L of channel fits `ch` (constants dropped).
    pub fn channels(&self, ch: &[ChannelFit]) -> f64 {
        match self {
            Likelihood::Time(n_eff) => neg_log_lik(ch, n_eff),
            Likelihood::Band => {
                ch.iter().filter_map(|c| c.band).map(|b: BandFit| b.neg_log_lik).sum()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_kinds_read_their_own_fields_of_a_channel() {
        let mut c = ChannelFit::with_neg_log_lik(3.0);
        assert!((Likelihood::Time(&[2.0]).channels(&[c.clone()]) - 3.0).abs() < 1e-12);
        c.band = Some(BandFit { neg_log_lik: -7.5, bins: 40 });
        assert_eq!(Likelihood::Band.channels(&[c.clone()]), -7.5);
        c.band = None;
        assert_eq!(Likelihood::Band.channels(&[c]), 0.0, "no bins: the channel does not count");
        assert_eq!(LikelihoodKind::Band.with(&[1.0]), Likelihood::Band);
        assert_eq!(LikelihoodKind::Time.with(&[1.0]), Likelihood::Time(&[1.0]));
    }
}
