//! The calibration parameters of seed Table 6.1 (section and stiffness
//! values, units as in the model: mm², MPa, mm⁴, N/mm) with their uniform
//! prior bounds, and the values a generated model uses.

use std::collections::BTreeMap;

/// One named parameter: unit and prior bounds (seed Table 6.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamInfo {
    /// Name as in the table.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Lower prior bound.
    pub low: f64,
    /// Upper prior bound.
    pub high: f64,
    /// Whether the generated model uses it (connection springs are not modelled yet).
    pub modelled: bool,
}

const fn p(
    name: &'static str,
    unit: &'static str,
    low: f64,
    high: f64,
    modelled: bool,
) -> ParamInfo {
    ParamInfo { name, unit, low, high, modelled }
}

/// The 15 parameters of seed Table 6.1.
pub const PARAMETERS: [ParamInfo; 15] = [
    p("A_cross", "mm2", 30.0, 36.0, true),
    p("E", "MPa", 1.9e5, 2.3e5, true),
    p("G", "MPa", 7.4e4, 8.2e4, true),
    p("J_cross", "mm4", 4800.0, 5100.0, true),
    p("Iy_cross", "mm4", 4000.0, 4700.0, true),
    p("Iz_cross", "mm4", 650.0, 750.0, true),
    p("K_rod", "-", 0.5, 3.0, false),
    p("K_friction", "N/mm", 15.0, 25.0, true),
    p("K_cc1", "N/mm", 750.0, 850.0, false),
    p("K_cc2", "N/mm", 75.0, 125.0, false),
    p("K_cc3", "N/mm", 10.0, 35.0, false),
    p("A_main", "mm2", 35.0, 42.0, true),
    p("J_main", "mm4", 7900.0, 8500.0, true),
    p("Iy_main", "mm4", 7250.0, 7800.0, true),
    p("K_mc", "N/mm", 1400.0, 1600.0, false),
];

/// Why a parameter value is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// Not one of the 15 names.
    #[error("parameter `{name}`: unknown (known: {known})")]
    Unknown {
        /// The name given.
        name: String,
        /// The known names.
        known: String,
    },
    /// A grid-connection parameter: the generated model has rigid connections.
    #[error(
        "parameter `{name}`: grid-connection springs are not modelled yet (connections are rigid)"
    )]
    NotModelled {
        /// The name given.
        name: String,
    },
    /// Not a finite positive number.
    #[error("parameter `{name}` = {value}: expected a finite number > 0")]
    Value {
        /// The name.
        name: String,
        /// The value.
        value: f64,
    },
    /// `NAME=VALUE` syntax error.
    #[error("`{text}`: expected NAME=VALUE")]
    Syntax {
        /// The text given.
        text: String,
    },
}

/// Values of the modelled parameters by name.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    values: BTreeMap<&'static str, f64>,
}

impl Parameters {
    /// Every modelled parameter at its prior mid-point.
    pub fn prior_midpoints() -> Self {
        let values = PARAMETERS
            .iter()
            .filter(|p| p.modelled)
            .map(|p| (p.name, 0.5 * (p.low + p.high)))
            .collect();
        Parameters { values }
    }

    /// Sets one parameter by name.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let info = PARAMETERS.iter().find(|p| p.name == name).ok_or_else(|| {
            ParamError::Unknown { name: name.into(), known: PARAMETERS.map(|p| p.name).join(", ") }
        })?;
        if !info.modelled {
            return Err(ParamError::NotModelled { name: name.into() });
        }
        if !(value > 0.0 && value.is_finite()) {
            return Err(ParamError::Value { name: name.into(), value });
        }
        self.values.insert(info.name, value);
        Ok(())
    }

    /// Parses and sets `NAME=VALUE`.
    pub fn set_text(&mut self, text: &str) -> Result<(), ParamError> {
        let syntax = || ParamError::Syntax { text: text.into() };
        let (name, value) = text.split_once('=').ok_or_else(syntax)?;
        let value: f64 = value.trim().parse().map_err(|_| syntax())?;
        self.set(name.trim(), value)
    }

    /// The value of a modelled parameter.
    pub fn get(&self, name: &str) -> f64 {
        self.values.get(name).copied().unwrap_or(f64::NAN)
    }

    /// All values, by name.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.values.iter().map(|(k, v)| (*k, *v))
    }
}
