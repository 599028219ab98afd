//! The causes a diagnosis can name (`ceiling-diagnosis/1` vocabulary) and
//! the model variant each stands for: the baseline (`none`: elastic
//! perimeter springs, elastic grid connections) and one extension per
//! missing physics, each with its extra parameters and their priors.

use fe::generator::{Connections, ModelOptions, Perimeter};

/// A named cause (and the model variant that adds its physics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Cause {
    /// The baseline explains the data within its noise.
    None,
    /// Grid ends strike the wall angle once the gap closes.
    PerimeterPounding,
    /// Stick-slip at the perimeter supports and seismic clips.
    PerimeterFriction,
    /// Nonlinear, softening and pinching grid connections.
    ConnectionHysteresis,
}

/// A uniform prior on one parameter (log-uniform when `log`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prior {
    /// Parameter name (an `fe::generator` name, or `damping_ratio`).
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Lower bound.
    pub low: f64,
    /// Upper bound.
    pub high: f64,
    /// Uniform in log(value) rather than in value.
    pub log: bool,
}

impl Prior {
    /// The value at unit-cube coordinate `u` in [0, 1].
    pub fn at(&self, u: f64) -> f64 {
        if self.log {
            (self.low.ln() + u * (self.high.ln() - self.low.ln())).exp()
        } else {
            self.low + u * (self.high - self.low)
        }
    }

    /// The unit-cube coordinate of `value`.
    pub fn unit(&self, value: f64) -> f64 {
        if self.log {
            (value.ln() - self.low.ln()) / (self.high.ln() - self.low.ln())
        } else {
            (value - self.low) / (self.high - self.low)
        }
    }
}

/// Parameters every variant calibrates: the perimeter spring stiffness
/// (Table 6.1's U(15, 25) N/mm widened to 8–40 N/mm: a bundle may come
/// from another specimen) and the Rayleigh damping ratio.
pub const BASELINE_PRIORS: [Prior; 2] = [
    Prior { name: "K_friction", unit: "N/mm", low: 8.0, high: 40.0, log: true },
    Prior { name: "damping_ratio", unit: "-", low: 0.01, high: 0.10, log: true },
];

/// Gap over nominal gap, 0.002–1.2: from a grid end touching the wall angle
/// (0.04 mm at a 19 mm nominal gap) to 20 % wider than nominal.
const POUNDING: [Prior; 1] =
    [Prior { name: "gap_ratio", unit: "-", low: 0.002, high: 1.2, log: true }];
const FRICTION: [Prior; 1] =
    [Prior { name: "friction_fy_N", unit: "N", low: 0.3, high: 30.0, log: true }];
const CONNECTION: [Prior; 2] = [
    Prior { name: "conn_force_scale", unit: "-", low: 0.05, high: 3.0, log: true },
    Prior { name: "conn_disp_scale", unit: "-", low: 0.2, high: 5.0, log: true },
];

impl Cause {
    /// Every cause, the baseline first.
    pub const ALL: [Cause; 4] = [
        Cause::None,
        Cause::PerimeterPounding,
        Cause::PerimeterFriction,
        Cause::ConnectionHysteresis,
    ];

    /// The spelling in `diagnosis.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Cause::None => "none",
            Cause::PerimeterPounding => "perimeter-pounding",
            Cause::PerimeterFriction => "perimeter-friction",
            Cause::ConnectionHysteresis => "connection-hysteresis",
        }
    }

    /// Parses a spelling of [`Cause::as_str`].
    pub fn parse(text: &str) -> Option<Cause> {
        Cause::ALL.into_iter().find(|c| c.as_str() == text)
    }

    /// The FE model options of this variant.
    pub fn model_options(self) -> ModelOptions {
        let (perimeter, connections) = match self {
            Cause::None => (Perimeter::Linear, Connections::Elastic),
            Cause::PerimeterPounding => (Perimeter::Pounding, Connections::Elastic),
            Cause::PerimeterFriction => (Perimeter::Friction, Connections::Elastic),
            Cause::ConnectionHysteresis => (Perimeter::Linear, Connections::Pinching4),
        };
        ModelOptions { perimeter, connections }
    }

    /// The extra parameters of this variant (none for the baseline).
    pub fn extra_priors(self) -> &'static [Prior] {
        match self {
            Cause::None => &[],
            Cause::PerimeterPounding => &POUNDING,
            Cause::PerimeterFriction => &FRICTION,
            Cause::ConnectionHysteresis => &CONNECTION,
        }
    }

    /// Baseline priors followed by the extra ones.
    pub fn priors(self) -> Vec<Prior> {
        BASELINE_PRIORS.iter().chain(self.extra_priors()).copied().collect()
    }

    /// What the physics is, in a sentence for the report.
    pub fn explain(self) -> &'static str {
        match self {
            Cause::None => "the baseline model explains the data within its noise",
            Cause::PerimeterPounding => "grid ends strike the wall angle once the gap closes",
            Cause::PerimeterFriction => "the perimeter supports stick, then slip",
            Cause::ConnectionHysteresis => "the grid connections soften, yield and pinch",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_round_trip_and_priors_map_both_ways() {
        for c in Cause::ALL {
            assert_eq!(Cause::parse(c.as_str()), Some(c));
            for p in c.priors() {
                for u in [0.0, 0.3, 1.0] {
                    assert!((p.unit(p.at(u)) - u).abs() < 1e-12, "{p:?}");
                }
            }
        }
        assert_eq!(Cause::parse("pounding"), None);
    }
}
