//! Which likelihood scores a point's channel fits. Each adds the identified
//! frequencies' term ([`super::modal_fit`]) where a point has it.
//!
//! - **Time**: the profiled Gaussian of the whole residual, channel c
//!   counting n_eff[c] = n(1−ρ)/(1+ρ) samples (what the calibration's
//!   searches minimise). Its nats double with the sampling rate where the
//!   residual is mostly white sensor noise (the demo campaign: pounding
//!   over `none` by 3201 nats at 100 Hz, 6380 at 200 Hz).
//! - **Band**: the profiled Gaussian of the residual within the model's
//!   band ([`super::band_likelihood::model_band_hz`]), channel c counting
//!   the Satterthwaite degrees of freedom of its in-band mean square
//!   ([`super::band_likelihood::BandFit::dof`]), both fixed by the band and
//!   the residual's spectral shape, not by the sampling rate. Misfits weigh
//!   by their power, as in time.
//! - **Whittle**: the periodogram within the band, its level profiled per
//!   sub-band. Every bin counts alike, so bins where the record holds
//!   little but noise and impacts decide: a model that predicts the
//!   impacts of pounding out of phase doubles the residual's power there.
//!   Measured on the demo campaign (pounding hidden): pounding 315 nats
//!   below `none`. Kept to be compared, not as a default.

use super::fit::{neg_log_lik, ChannelFit};

/// The diagnosis's channel weights, fixed from the baseline's residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelWeights<'a> {
    /// Effective sample sizes n(1−ρ)/(1+ρ) ([`super::fit::effective_sizes`]).
    pub n_eff: &'a [f64],
    /// In-band degrees of freedom ([`band_sizes`]).
    pub band_dof: &'a [f64],
}

/// A likelihood of channel fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Likelihood<'a> {
    /// Profiled Gaussian in time under effective sample sizes
    /// ([`super::fit::neg_log_lik`]).
    Time(&'a [f64]),
    /// Profiled Gaussian of the in-band residual under in-band degrees of
    /// freedom: Σ_c dof_c / 2 · ln(mean square_c); channels without bins in
    /// the band do not count.
    Band(&'a [f64]),
    /// Whittle over the band, the level profiled per sub-band
    /// ([`super::band_likelihood::band_neg_log_lik`]).
    Whittle,
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
    /// [`Likelihood::Whittle`].
    Whittle,
}

impl LikelihoodKind {
    /// This kind with the diagnosis's channel weights `w`.
    pub fn with<'a>(self, w: ChannelWeights<'a>) -> Likelihood<'a> {
        match self {
            LikelihoodKind::Time => Likelihood::Time(w.n_eff),
            LikelihoodKind::Band => Likelihood::Band(w.band_dof),
            LikelihoodKind::Whittle => Likelihood::Whittle,
        }
    }

    /// Its name in `diagnosis.json`, the report and the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            LikelihoodKind::Time => "time",
            LikelihoodKind::Band => "band",
            LikelihoodKind::Whittle => "whittle",
        }
    }

    /// The kind named `name` ([`as_str`](Self::as_str)).
    pub fn parse(name: &str) -> Option<LikelihoodKind> {
        [LikelihoodKind::Time, LikelihoodKind::Band, LikelihoodKind::Whittle]
            .into_iter()
            .find(|k| k.as_str() == name)
    }
}

impl Likelihood<'_> {
    /// −ln L of channel fits `ch` (constants dropped).
    pub fn channels(&self, ch: &[ChannelFit]) -> f64 {
        match self {
            Likelihood::Time(n_eff) => neg_log_lik(ch, n_eff),
            Likelihood::Band(dof) => (ch.iter().zip(*dof))
                .filter_map(|(c, d)| c.band.map(|b| 0.5 * d * b.mean_square.max(1e-300).ln()))
                .sum(),
            Likelihood::Whittle => ch.iter().filter_map(|c| c.band).map(|b| b.neg_log_lik).sum(),
        }
    }
}

/// In-band degrees of freedom of channels (0 without bins in the band).
pub fn band_sizes(ch: &[ChannelFit]) -> Vec<f64> {
    ch.iter().map(|c| c.band.map_or(0.0, |b| b.dof)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::band_likelihood::BandFit;

    #[test]
    fn each_kind_reads_its_own_fields_of_a_channel() {
        let mut c = ChannelFit::with_neg_log_lik(3.0);
        assert!((Likelihood::Time(&[2.0]).channels(&[c.clone()]) - 3.0).abs() < 1e-12);
        c.band = Some(BandFit { neg_log_lik: -7.5, bins: 40, mean_square: 2.0, dof: 60.0 });
        assert_eq!(Likelihood::Whittle.channels(&[c.clone()]), -7.5);
        let band = Likelihood::Band(&[10.0]).channels(&[c.clone()]);
        assert!((band - 5.0 * 2f64.ln()).abs() < 1e-12, "{band}");
        assert_eq!(band_sizes(&[c.clone()]), vec![60.0]);
        c.band = None;
        assert_eq!(Likelihood::Whittle.channels(&[c.clone()]), 0.0, "no bins: not counted");
        assert_eq!(Likelihood::Band(&[10.0]).channels(&[c.clone()]), 0.0);
        assert_eq!(band_sizes(&[c]), vec![0.0]);
        let w = ChannelWeights { n_eff: &[1.0], band_dof: &[2.0] };
        assert_eq!(LikelihoodKind::Band.with(w), Likelihood::Band(&[2.0]));
        assert_eq!(LikelihoodKind::Time.with(w), Likelihood::Time(&[1.0]));
        for k in [LikelihoodKind::Time, LikelihoodKind::Band, LikelihoodKind::Whittle] {
            assert_eq!(LikelihoodKind::parse(k.as_str()), Some(k));
        }
        assert_eq!(LikelihoodKind::parse("fourier"), None);
    }
}
