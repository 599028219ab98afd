//! `[[model.sensors]]` of the `ceiling` kind: named sensors at plan
//! positions (m, origin at a ceiling corner), reading absolute acceleration
//! (m/s²) or displacement relative to the base (m) in x or y; each becomes
//! an [`fe::ceiling::Sensor`] and one history of the run.

use fe::ceiling::{Direction, Sensor, SensorKind};
use serde::{Deserialize, Serialize};

/// What a sensor measures (`kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SensorKindOption {
    /// Absolute acceleration (m/s²).
    Acceleration,
    /// Displacement relative to the base (m).
    Displacement,
}

/// Measuring direction (`direction`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DirectionOption {
    /// Along x.
    X,
    /// Along y.
    Y,
}

/// One `[[model.sensors]]` table.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SensorOptions {
    /// Identifier: letters, digits, `_`, `-` or `.` (it names a history).
    pub id: String,
    /// What it measures.
    pub kind: SensorKindOption,
    /// Plan position x (m); a number or its exact decimal text.
    #[serde(with = "crate::exact_json::f64_text")]
    pub x_m: f64,
    /// Plan position y (m); a number or its exact decimal text.
    #[serde(with = "crate::exact_json::f64_text")]
    pub y_m: f64,
    /// Measuring direction.
    pub direction: DirectionOption,
}

impl SensorOptions {
    /// Parses `[[model.sensors]]` number `k` (as JSON); an error names the
    /// key (`model.sensors[k].kind`, ...) and what was expected.
    pub fn from_json(v: &serde_json::Value, k: usize) -> Result<Self, String> {
        let key = format!("model.sensors[{k}]");
        let Some(obj) = v.as_object() else {
            return Err(format!("{key}: {v}: expected a table"));
        };
        for (field, expected) in
            [("kind", "\"acceleration\" or \"displacement\""), ("direction", "\"x\" or \"y\"")]
        {
            let bad = match (field, obj.get(field)) {
                ("kind", Some(x)) => serde_json::from_value::<SensorKindOption>(x.clone()).is_err(),
                (_, Some(x)) => serde_json::from_value::<DirectionOption>(x.clone()).is_err(),
                _ => false,
            };
            if bad {
                return Err(format!("{key}.{field} = {}: expected {expected}", obj[field]));
            }
        }
        serde_json::from_value(v.clone()).map_err(|e| format!("{key}: {e}"))
    }

    /// The FE sensor.
    pub fn sensor(&self) -> Sensor {
        Sensor {
            id: self.id.clone(),
            kind: match self.kind {
                SensorKindOption::Acceleration => SensorKind::Acceleration,
                SensorKindOption::Displacement => SensorKind::Displacement,
            },
            x_m: self.x_m,
            y_m: self.y_m,
            direction: match self.direction {
                DirectionOption::X => Direction::X,
                DirectionOption::Y => Direction::Y,
            },
        }
    }

    /// Name of the sensor's history channel, unit included
    /// (`<id>_accel_m_s2` or `<id>_disp_m`).
    pub fn channel(&self) -> String {
        match self.kind {
            SensorKindOption::Acceleration => format!("{}_accel_m_s2", self.id),
            SensorKindOption::Displacement => format!("{}_disp_m", self.id),
        }
    }
}

/// Whether `id` can name a history (and a file of `ceilfarm export`).
pub fn id_ok(id: &str) -> bool {
    !id.is_empty() && id.chars().all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
}
