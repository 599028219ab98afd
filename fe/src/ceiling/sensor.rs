//! Sensors at plan positions (m, origin at a ceiling corner; bundle frame):
//! absolute acceleration or displacement relative to the base, in x or y.
//! A position between grid nodes reads the bilinear interpolation of the
//! surrounding grid nodes (linear along a member when on one; a room corner,
//! which has no node, is left out and the weights renormalised).

use std::collections::HashMap;

use crate::model::Model;

/// What a sensor measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorKind {
    /// Absolute acceleration (m/s²).
    Acceleration,
    /// Displacement relative to the base (m).
    Displacement,
}

/// Horizontal measuring direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Along x (cross tees).
    X,
    /// Along y (main tees).
    Y,
}

impl Direction {
    /// Global DOF (1 or 2).
    pub fn dof(self) -> u8 {
        match self {
            Direction::X => 1,
            Direction::Y => 2,
        }
    }
}

/// One sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Identifier (its column name in run files).
    pub id: String,
    /// Acceleration or displacement.
    pub kind: SensorKind,
    /// Plan position x (m).
    pub x_m: f64,
    /// Plan position y (m).
    pub y_m: f64,
    /// Measuring direction.
    pub direction: Direction,
}

/// Grid nodes and weights that a sensor reads.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// (node id, weight), weights summing to 1.
    pub nodes: Vec<(u64, f64)>,
}

/// Why a sensor cannot be placed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("sensor {id} at ({x_m} m, {y_m} m): {message}")]
pub struct PlacementError {
    /// Sensor id.
    pub id: String,
    /// Position x (m).
    pub x_m: f64,
    /// Position y (m).
    pub y_m: f64,
    /// What is wrong.
    pub message: String,
}

/// Places a sensor on the grid nodes of a generated model (grid node (i, j)
/// at (i·module, j·module, 0) mm, as [`crate::generator`] numbers them).
pub fn place(
    s: &Sensor,
    model: &Model,
    module_m: f64,
    nx: usize,
    ny: usize,
) -> Result<Placement, PlacementError> {
    let err =
        |message: String| PlacementError { id: s.id.clone(), x_m: s.x_m, y_m: s.y_m, message };
    let (lx, ly) = (nx as f64 * module_m, ny as f64 * module_m);
    let tol = 1e-9 * module_m;
    if !(s.x_m >= -tol && s.x_m <= lx + tol && s.y_m >= -tol && s.y_m <= ly + tol) {
        return Err(err(format!("outside the ceiling (0..{lx} m, 0..{ly} m)")));
    }
    let coords: HashMap<u64, [f64; 3]> = model.nodes.iter().map(|n| (n.id, n.xyz_mm)).collect();
    let cell = |v: f64, n: usize| {
        let r = (v / module_m).clamp(0.0, n as f64);
        let i = (r.floor() as usize).min(n.saturating_sub(1));
        (i, r - i as f64)
    };
    let ((i, fx), (j, fy)) = (cell(s.x_m, nx), cell(s.y_m, ny));
    let mut nodes = Vec::new();
    for (di, wx) in [(0, 1.0 - fx), (1, fx)] {
        for (dj, wy) in [(0, 1.0 - fy), (1, fy)] {
            let w = wx * wy;
            if w <= 1e-12 {
                continue;
            }
            let (a, b) = (i + di, j + dj);
            let id = (1 + a + (nx + 1) * b) as u64;
            let at = [a as f64 * module_m * 1e3, b as f64 * module_m * 1e3];
            match coords.get(&id) {
                Some(xyz) if (xyz[0] - at[0]).abs() < 1e-6 && (xyz[1] - at[1]).abs() < 1e-6 => {
                    nodes.push((id, w))
                }
                _ => {}
            }
        }
    }
    let total: f64 = nodes.iter().map(|(_, w)| w).sum();
    if nodes.is_empty() || total < 1e-9 {
        return Err(err("no grid node near this position".into()));
    }
    nodes.iter_mut().for_each(|(_, w)| *w /= total);
    Ok(Placement { nodes })
}
