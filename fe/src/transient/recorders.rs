//! Recorded channels: node displacement / velocity relative to the base,
//! absolute acceleration (relative + a_g of the component in that DOF), spring
//! deformation d = u_j − u_i and material force (MODEL_FORMAT.md, recorders).
//!
//! Units: mm, mm/s, mm/s², N (rad for rotational DOFs).

use super::newton::Kinematics;
use super::spec::RecorderSpec;
use super::springs::SpringStates;
use super::TransientError;
use crate::assembly::Structure;

/// What one channel reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Channel {
    /// Relative displacement of an equation (fixed DOF: 0).
    Disp(Option<usize>),
    /// Relative velocity.
    Vel(Option<usize>),
    /// Relative acceleration plus a_g of the base component in that DOF.
    AccelAbs {
        /// Equation (fixed DOF: relative acceleration 0).
        eq: Option<usize>,
        /// The base-motion component acting in the DOF, if any.
        ground: Option<usize>,
    },
    /// Deformation of spring number k (file order).
    SpringDeformation(usize),
    /// Force of spring number k.
    SpringForce(usize),
}

/// The channels of an analysis, with their column names.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorders {
    /// Column names, one per channel.
    pub names: Vec<String>,
    /// Channels.
    pub channels: Vec<Channel>,
}

impl Recorders {
    /// Resolves recorder specs against a structure; `ground_dofs` are the
    /// DOFs (1..6) of the base-motion components, in component order.
    pub fn new(
        specs: &[RecorderSpec],
        s: &Structure,
        ground_dofs: &[u8],
    ) -> Result<Self, TransientError> {
        let mut names = Vec::new();
        let mut channels = Vec::new();
        for r in specs {
            let (name, ch) = resolve(r, s, ground_dofs)?;
            names.push(name);
            channels.push(ch);
        }
        Ok(Recorders { names, channels })
    }

    /// Appends one value per channel to `row`; `ag` holds a_g per component.
    pub fn sample(&self, kin: &Kinematics, springs: &SpringStates, ag: &[f64], row: &mut Vec<f64>) {
        let at = |x: &[f64], eq: Option<usize>| eq.map_or(0.0, |e| x[e]);
        for ch in &self.channels {
            row.push(match *ch {
                Channel::Disp(eq) => at(&kin.u, eq),
                Channel::Vel(eq) => at(&kin.v, eq),
                Channel::AccelAbs { eq, ground } => at(&kin.a, eq) + ground.map_or(0.0, |c| ag[c]),
                Channel::SpringDeformation(k) => springs.deformation_mm[k],
                Channel::SpringForce(k) => springs.material_force_n[k],
            });
        }
    }
}

fn bad(r: &RecorderSpec, message: &str) -> TransientError {
    TransientError::Recorder { recorder: format!("{r:?}"), message: message.into() }
}

fn resolve(
    r: &RecorderSpec,
    s: &Structure,
    ground_dofs: &[u8],
) -> Result<(String, Channel), TransientError> {
    if let Some(node) = r.node {
        let dof = r
            .dof
            .filter(|d| (1..=6).contains(d))
            .ok_or_else(|| bad(r, "node recorder needs dof 1..6"))?;
        s.dofs.node_index(node).ok_or_else(|| bad(r, "unknown node"))?;
        let eq = s.dofs.node_eqs(node)[usize::from(dof) - 1];
        let ch = match r.response.as_str() {
            "disp" => Channel::Disp(eq),
            "vel" => Channel::Vel(eq),
            "accel_abs" => {
                Channel::AccelAbs { eq, ground: ground_dofs.iter().position(|d| *d == dof) }
            }
            _ => return Err(bad(r, "node response must be disp, vel or accel_abs")),
        };
        let name = r.name.clone().unwrap_or_else(|| format!("n{node}_dof{dof}_{}", r.response));
        return Ok((name, ch));
    }
    let id = r.element.ok_or_else(|| bad(r, "recorder needs a node or an element"))?;
    let k = s
        .springs
        .iter()
        .position(|sp| sp.id == id)
        .ok_or_else(|| bad(r, "element is not a spring"))?;
    let ch = match r.response.as_str() {
        "deformation" => Channel::SpringDeformation(k),
        "force" => Channel::SpringForce(k),
        _ => return Err(bad(r, "spring response must be deformation or force")),
    };
    Ok((r.name.clone().unwrap_or_else(|| format!("e{id}_{}", r.response)), ch))
}
