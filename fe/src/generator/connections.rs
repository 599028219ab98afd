//! Grid connections as zero-length springs (seed 5.1.1: "ZeroLength element
//! with Pinching4 material to model the axial nonlinear behavior of grid
//! connection"), written when `[model] connections` is not `rigid`.
//!
//! Layout:
//! - tee joints: where a member ends at a continuous one, each ending
//!   piece gets its own node, coincident with the grid node and joined to it
//!   by six springs in the ending member's axes: axial K_cc1 (or the scaled
//!   CJS-A Pinching4), in-plane transverse K_cc2 (or, when
//!   `conn_transverse_force_scale` is given, a CJS-A Pinching4 too),
//!   vertical K_cc3 (Table 6.1:
//!   X, Y, Z for the cross tees), rotations [`ROTATION_N_MM_PER_RAD`] (in
//!   the plane `K_joint_rot` when given: a semi-rigid joint). The
//!   cross tees end at the main tees; the sub cross tees end at the cross
//!   tees, a joint the seed (4.2.2) calls basically identical to the
//!   main-cross tee joint, so it gets the same springs.
//! - main-tee splices: main tees come in 3600 mm pieces (seed Table 4.4;
//!   "4 pieces of main tees and 3 connections" on a 12 m line, 4.4), laid
//!   from the y = 0 wall, so a splice sits at every interior grid node of a
//!   main-tee line at a multiple of 3600 mm; the piece above it gets its own
//!   node joined by K_mc along the main tee (y), [`SPLICE_RESTRAINT_N_PER_MM`]
//!   across and vertically, and [`ROTATION_N_MM_PER_RAD`] in rotation. The
//!   splice stays elastic in the `pinching4` variant (the seed's Takeda
//!   splice law of 5.4.1 is not used).
//!
//! Spring orientation: node i is the piece before the joint in +x / +y, so
//! that d > 0 is tension (pull-out) of the joint at either end, as the
//! positive side of the CJS-A backbone. Node ids: the ending piece before
//! the joint 300000 + grid id, after it 400000 + grid id, the spliced piece
//! 500000 + grid id; springs from 300001; masses stay on the grid nodes.
//! Units: N, mm, rad.

use super::grid::{Grid, Member};
use super::params::Parameters;
use super::spec::{CeilingSpec, Connections};
use crate::materials::{MaterialSpec, Pinching4Spec};
use crate::model::{MaterialDef, Model, Node, Spring};

/// Rotational stiffness of every connection spring (N·mm/rad): continuity,
/// about 1e6 times the main tee's 4EI/L over a 600 mm module (1.05e7), so
/// that frequencies differ from the rigid grid's by less than 1e-6.
pub const ROTATION_N_MM_PER_RAD: f64 = 1e13;
/// Transverse and vertical stiffness of a main-tee splice (N/mm): continuity,
/// about 700 times the main tee's EA/L over a 600 mm module (1.4e4). Much
/// stiffer translational springs put a round-off floor under Newton's
/// increment: at 1e10 N/mm a type-C run stalls at ‖Δu‖ = 3.3e-10 mm, above
/// the transient's 1e-10 mm tolerance.
pub const SPLICE_RESTRAINT_N_PER_MM: f64 = 1e7;
/// Main-tee piece length (mm, seed Table 4.4).
pub const MAIN_TEE_PIECE_MM: f64 = 3600.0;

/// Pinching4 rForce of the seed's CJS-A set (Table 5.4), both sides.
pub const CJS_A_RELOAD_FORCE: f64 = 0.2;
/// Pinching4 uForce of the seed's CJS-A set (Table 5.4), both sides.
pub const CJS_A_UNLOAD_FORCE: f64 = -0.01;

/// The CJS-A backbone's first slope in compression (200 N at 0.5 mm) over
/// its first slope in tension (150 N at 0.5 mm), Table 5.4.
pub const CJS_A_COMPRESSION_RATIO: f64 = 4.0 / 3.0;

/// The seed's CJS-A Pinching4 set (Table 5.4) with forces times
/// `force_scale` and deformations times `disp_scale`.
pub fn cjs_a(force_scale: f64, disp_scale: f64) -> Pinching4Spec {
    let f = |v: [f64; 4]| v.map(|x| x * force_scale);
    let d = |v: [f64; 4]| v.map(|x| x * disp_scale);
    Pinching4Spec {
        ePf: f([150.0, 651.0, 1001.0, 458.0]),
        ePd: d([0.5, 5.5, 10.5, 13.8]),
        eNf: f([-200.0, -620.0, -1248.0, -556.0]),
        eNd: d([-0.5, -5.0, -12.7, -16.0]),
        rDispP: 0.6,
        rForceP: CJS_A_RELOAD_FORCE,
        uForceP: CJS_A_UNLOAD_FORCE,
        rDispN: 0.6,
        rForceN: CJS_A_RELOAD_FORCE,
        uForceN: CJS_A_UNLOAD_FORCE,
        gK: [0.0; 4],
        gKLim: 0.0,
        gD: [0.0; 4],
        gDLim: 0.0,
        gF: [0.0; 4],
        gFLim: 0.0,
        gE: 1.0,
        dmgType: "cycle".into(),
    }
}

/// Moves the first compression deformation of `set` so that its first
/// slope in compression is `ratio` times its first slope in tension; every
/// other backbone point stays. (Table 5.4's own numbers are kept untouched
/// at [`CJS_A_COMPRESSION_RATIO`], which this rebuilds to round-off.)
pub fn set_compression_ratio(set: &mut Pinching4Spec, ratio: f64) {
    let tension_n_per_mm = set.ePf[0] / set.ePd[0];
    set.eNd[0] = set.eNf[0] / (ratio * tension_n_per_mm);
}

/// Material ids of the connection springs.
struct Mats {
    axial: u64,
    transverse: u64,
    vertical: u64,
    splice_axial: u64,
    splice_restraint: u64,
    rotation: u64,
    /// The tee joints' rotation in the plane (about z): `rotation` unless
    /// `K_joint_rot` sets its own.
    plan_rotation: u64,
}

/// Appends the connection materials after the existing ones.
fn materials(spec: &CeilingSpec, p: &Parameters, m: &mut Model) -> Mats {
    let pinching4 = spec.model.connections == Connections::Pinching4;
    let axial = if pinching4 {
        joint_set(p, "conn_force_scale", "conn_disp_scale")
    } else {
        MaterialSpec::Elastic { k: p.value_or_midpoint("K_cc1") }
    };
    let transverse = if pinching4 && p.value_or_midpoint("conn_transverse_force_scale") > 0.0 {
        joint_set(p, "conn_transverse_force_scale", "conn_transverse_disp_scale")
    } else {
        MaterialSpec::Elastic { k: p.value_or_midpoint("K_cc2") }
    };
    let list = [
        axial,
        transverse,
        MaterialSpec::Elastic { k: p.value_or_midpoint("K_cc3") },
        MaterialSpec::Elastic { k: p.value_or_midpoint("K_mc") },
        MaterialSpec::Elastic { k: SPLICE_RESTRAINT_N_PER_MM },
        MaterialSpec::Elastic { k: ROTATION_N_MM_PER_RAD },
    ];
    let first = m.materials.len() as u64 + 1;
    for (k, spec) in list.into_iter().enumerate() {
        m.materials.push(MaterialDef { id: first + k as u64, spec });
    }
    let k_plan = p.value_or_midpoint("K_joint_rot");
    let plan_rotation = if k_plan == ROTATION_N_MM_PER_RAD {
        first + 5
    } else {
        m.materials.push(MaterialDef { id: first + 6, spec: MaterialSpec::Elastic { k: k_plan } });
        first + 6
    };
    Mats {
        axial: first,
        transverse: first + 1,
        vertical: first + 2,
        splice_axial: first + 3,
        splice_restraint: first + 4,
        rotation: first + 5,
        plan_rotation,
    }
}

/// A tee joint's CJS-A Pinching4 spring, its forces and deformations times
/// the parameters named `force` and `disp`, its pinching, unloading and
/// compression ratio the joint's (`conn_reload_force`, `conn_unload_shift`,
/// `conn_compression_ratio`).
fn joint_set(p: &Parameters, force: &str, disp: &str) -> MaterialSpec {
    let mut set = cjs_a(p.value_or_midpoint(force), p.value_or_midpoint(disp));
    let reload = p.value_or_midpoint("conn_reload_force");
    (set.rForceP, set.rForceN) = (reload, reload);
    let unload = CJS_A_UNLOAD_FORCE + p.value_or_midpoint("conn_unload_shift");
    (set.uForceP, set.uForceN) = (unload, unload);
    let ratio = p.value_or_midpoint("conn_compression_ratio");
    if ratio != CJS_A_COMPRESSION_RATIO {
        set_compression_ratio(&mut set, ratio);
    }
    MaterialSpec::Pinching4(Box::new(set))
}

/// One connection: the grid node, the piece's node, the piece's axis DOF
/// (1 x, 2 y), whether the piece lies after the joint, the joint kind.
struct Joint {
    grid: u64,
    piece: u64,
    axis: u8,
    after: bool,
    member: Member,
    splice: bool,
    xyz_mm: [f64; 3],
}

/// Every connection of the grid, in a fixed order (by grid node, then kind):
/// where a y-line's member crosses a row's cross tee, the cross tee's
/// pieces end at a main tee and a sub cross tee's pieces end at the cross
/// tee (a piece on each side the grid goes on; one on a wall line), and a
/// main tee between the walls is spliced every [`MAIN_TEE_PIECE_MM`].
fn joints(g: &Grid) -> Vec<Joint> {
    let mut out = vec![];
    let columns = g.y_line_columns();
    for j in g.cross_rows() {
        for &i in &columns {
            let grid = g.id(i, j);
            let xyz_mm = [i as f64 * g.module_mm, j as f64 * g.module_mm, 0.0];
            let (member, axis, before, after) = match g.y_line(i) {
                Member::Main => (Member::Cross, 1, i > 0, i < g.nx),
                _ => (Member::Sub, 2, j > 0, j < g.ny),
            };
            // The piece before the joint and the one after, where the grid goes on.
            let pieces = [(false, 300000, before), (true, 400000, after)];
            for (after, base, _) in pieces.into_iter().filter(|p| p.2) {
                let piece = base + grid;
                out.push(Joint { grid, piece, axis, after, member, splice: false, xyz_mm });
            }
            let y_mm = j as f64 * g.module_mm;
            let k = (y_mm / MAIN_TEE_PIECE_MM).round();
            let inside = j > 0 && j < g.ny;
            if g.y_line(i) == Member::Main && inside && (y_mm - k * MAIN_TEE_PIECE_MM).abs() < 1e-6
            {
                let piece = 500000 + grid;
                let member = Member::Main;
                out.push(Joint { grid, piece, axis: 2, after: true, member, splice: true, xyz_mm });
            }
        }
    }
    out
}

/// Moves the beam end at `grid` of the piece described by `joint` to its node.
fn rewire(m: &mut Model, joint: &Joint) {
    let name = joint.member.name();
    for b in m.beams.iter_mut().filter(|b| b.group.as_deref() == Some(name)) {
        if joint.after && b.i == joint.grid {
            b.i = joint.piece;
        } else if !joint.after && b.j == joint.grid {
            b.j = joint.piece;
        }
    }
}

/// The six springs of one connection: (dof, material, direction name).
fn springs_of(joint: &Joint, mats: &Mats) -> [(u8, u64, &'static str); 6] {
    let across = if joint.axis == 1 { 2 } else { 1 };
    let (axial, transverse, vertical, plan) = if joint.splice {
        (mats.splice_axial, mats.splice_restraint, mats.splice_restraint, mats.rotation)
    } else {
        (mats.axial, mats.transverse, mats.vertical, mats.plan_rotation)
    };
    [
        (joint.axis, axial, "axial"),
        (across, transverse, "transverse"),
        (3, vertical, "vertical"),
        (4, mats.rotation, "rotation"),
        (5, mats.rotation, "rotation"),
        (6, plan, "rotation"),
    ]
}

/// Writes the connection nodes, materials and springs and moves the beam
/// ends onto the new nodes; returns the new nodes. No-op for rigid connections.
pub(super) fn connections(
    g: &Grid,
    spec: &CeilingSpec,
    p: &Parameters,
    m: &mut Model,
) -> Vec<Node> {
    if spec.model.connections == Connections::Rigid {
        return vec![];
    }
    let mats = materials(spec, p, m);
    let mut nodes = vec![];
    let mut next_id = 300001;
    for joint in joints(g) {
        rewire(m, &joint);
        nodes.push(Node { id: joint.piece, xyz_mm: joint.xyz_mm });
        let (a, b) =
            if joint.after { (joint.grid, joint.piece) } else { (joint.piece, joint.grid) };
        let kind = if joint.splice { "splice" } else { "connection" };
        for (dof, mat, dir) in springs_of(&joint, &mats) {
            m.springs.push(Spring {
                id: next_id,
                i: a,
                j: b,
                dof,
                mat,
                rayleigh: true,
                group: Some(format!("{kind}_{dir}")),
                side: None,
                member: Some(joint.member.name().into()),
            });
            next_id += 1;
        }
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn unscaled_set_is_table_5_4() {
        let s = cjs_a(1.0, 1.0);
        assert_eq!(s.ePf, [150.0, 651.0, 1001.0, 458.0]);
        assert_eq!(s.eNd, [-0.5, -5.0, -12.7, -16.0]);
        // OpenSees' eigen stiffness: the stiffer first slope, 200 N / 0.5 mm.
        assert_eq!(MaterialSpec::Pinching4(Box::new(s)).initial_tangent(), 400.0);
    }

    proptest! {
        #[test]
        fn scaled_sets_build_and_scale_the_slopes(fs in 0.5f64..1.5, ds in 0.5f64..1.5) {
            let spec = MaterialSpec::Pinching4(Box::new(cjs_a(fs, ds)));
            prop_assert!(crate::materials::build(&spec).is_ok());
            let k = spec.initial_tangent();
            prop_assert!((k - 400.0 * fs / ds).abs() <= 1e-12 * k);
        }
    }
}
