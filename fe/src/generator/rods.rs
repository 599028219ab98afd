//! The hanger rods: M8 beams from a main tee's grid node up to a top fixed
//! at the hanger length (the slab's anchor), on every main-tee line at the
//! hanger spacing. When the members carry their mass a rod is split into
//! [`ROD_ELEMENTS`] beams with its mass lumped along it, so that its own
//! bending modes (a rod swinging between its anchor and the tee, about
//! 20 Hz for a 1 m M8 rod pinned at the tee) are modes of the model as
//! they are of a specimen; massless rods stay one beam (a beam split
//! without mass between its nodes has the same stiffness). With
//! `K_rod_rot` below continuity a rod ends on its own node at the tee,
//! tied to the grid node in translation and in torsion and turning about
//! x and y through a rotational spring: a rod in a clip or a hanger wire's
//! loop, between pinned and the seed's rigid tie.
//!
//! Numbering: rod top 200000 + grid id; the rod's node at the tee (with a
//! hinge) 600000 + id; the k-th node up the rod (1 ≤ k < [`ROD_ELEMENTS`])
//! 600000 + 100000·k + id; hinge springs from 600001.

use super::connections::{ROTATION_N_MM_PER_RAD, SPLICE_RESTRAINT_N_PER_MM};
use super::grid::{push_beam, Grid, Member};
use super::params::{Parameters, MEMBER_KG_PER_M};
use crate::materials::MaterialSpec;
use crate::model::{MaterialDef, Model, Node, Spring};

/// Beams per rod when the rods carry mass: the first bending mode of a 1 m
/// M8 rod fixed at the top and pinned at the tee, with its mass lumped at
/// the nodes, lies 0.45 % below the continuous rod's (15.42/2π · √(EI/m)/L²,
/// 20.86 Hz) with three beams, 3.9 % with two and 0.11 % with four
/// (`rod_mode_against_continuous_rod` measures it); three keep the model
/// small (two nodes more per rod) at an error well below a specimen's
/// scatter of rod length (±3 % of length is ±6 % of frequency).
pub const ROD_ELEMENTS: usize = 3;

/// The rods of a model: their fixed tops, and the grid node and the rod's
/// own node at the tee of each hinged rod.
pub(super) struct Rods {
    /// The fixed top of each rod (200000 + grid id), at the hanger length.
    pub(super) tops: Vec<Node>,
    /// (grid node, rod node at the tee) of each rod when hinged.
    hinges: Vec<(u64, u64)>,
    /// Beams per rod.
    elements: usize,
}

/// The rods' section (A, J, Iy, Iz in mm², mm⁴): the M8 rod, 40 mm², its
/// bending inertia A²/4π times `rod_bending_factor`.
fn section(p: &Parameters) -> [f64; 4] {
    let area = 40.0;
    let i_mm4 =
        area * area / (4.0 * std::f64::consts::PI) * p.value_or_midpoint("rod_bending_factor");
    [area, 2.0 * i_mm4, i_mm4, i_mm4]
}

/// Whether the rods end on their own hinge node: `K_rod_rot` below continuity.
fn hinged(p: &Parameters) -> bool {
    p.value_or_midpoint("K_rod_rot") < ROTATION_N_MM_PER_RAD
}

/// The id of the k-th node up the rod hung from grid node `grid`
/// (1 ≤ k < [`ROD_ELEMENTS`]).
fn inner_node(grid: u64, k: usize) -> u64 {
    600000 + 100000 * k as u64 + grid
}

/// Appends every rod's nodes below the top and its beams; returns the rods.
pub(super) fn rods(g: &Grid, p: &Parameters, length_mm: f64, m: &mut Model) -> Rods {
    let sec = section(p);
    let elements = if p.value_or_midpoint("member_mass_factor") > 0.0 { ROD_ELEMENTS } else { 1 };
    let mut rods = Rods { tops: vec![], hinges: vec![], elements };
    for i in g.y_line_columns().into_iter().filter(|i| g.y_line(*i) == Member::Main) {
        for j in g.rod_rows() {
            let id = g.id(i, j);
            let at = |z_mm: f64| [i as f64 * g.module_mm, j as f64 * g.module_mm, z_mm];
            let mut chain = vec![id];
            if hinged(p) {
                m.nodes.push(Node { id: 600000 + id, xyz_mm: at(0.0) });
                rods.hinges.push((id, 600000 + id));
                chain = vec![600000 + id];
            }
            for k in 1..elements {
                let node = inner_node(id, k);
                m.nodes.push(Node { id: node, xyz_mm: at(length_mm * k as f64 / elements as f64) });
                chain.push(node);
            }
            rods.tops.push(Node { id: 200000 + id, xyz_mm: at(length_mm) });
            chain.push(200000 + id);
            for pair in chain.windows(2) {
                push_beam(m, pair[0], pair[1], sec, p, [1.0, 0.0, 0.0], "rod");
            }
        }
    }
    rods
}

/// The rods' own mass ([`MEMBER_KG_PER_M`]'s rod value times `factor`, t)
/// as (node, [x, y, z] mass): each beam's half on each of its nodes, the
/// lowest half on the grid node and the top half on the fixed top (lost).
/// The nodes up a rod carry it sideways only: along its axis a rod is
/// thousands of times stiffer than the grid, so their vertical modes (tens
/// of kHz) would add nothing but a spread of eigenvalues no eigensolver
/// resolves to round-off.
pub(super) fn rod_masses(rods: &Rods, factor: f64) -> Vec<(u64, [f64; 3])> {
    let mut out = vec![];
    for top in &rods.tops {
        let beam_t = factor * MEMBER_KG_PER_M[3] * top.xyz_mm[2] * 1e-6 / rods.elements as f64;
        let grid = top.id - 200000;
        out.push((grid, [0.5 * beam_t; 3]));
        for k in 1..rods.elements {
            out.push((inner_node(grid, k), [beam_t, beam_t, 0.0]));
        }
    }
    out
}

/// Ties each hinged rod's node at the tee to its grid node: stiff in the
/// three translations ([`SPLICE_RESTRAINT_N_PER_MM`]) and in torsion
/// ([`ROTATION_N_MM_PER_RAD`]), `K_rod_rot` about x and y. Materials after
/// the existing ones, springs from 600001.
pub(super) fn rod_hinges(rods: &Rods, p: &Parameters, m: &mut Model) {
    if rods.hinges.is_empty() {
        return;
    }
    let first = m.materials.iter().map(|d| d.id).max().unwrap_or(0) + 1;
    let stiffness =
        [SPLICE_RESTRAINT_N_PER_MM, p.value_or_midpoint("K_rod_rot"), ROTATION_N_MM_PER_RAD];
    for (k, stiffness) in stiffness.into_iter().enumerate() {
        m.materials.push(MaterialDef {
            id: first + k as u64,
            spec: MaterialSpec::Elastic { k: stiffness },
        });
    }
    let dofs = [(1, first), (2, first), (3, first), (4, first + 1), (5, first + 1), (6, first + 2)];
    let mut id = 600001;
    for &(grid, rod) in &rods.hinges {
        for (dof, mat) in dofs {
            m.springs.push(Spring {
                id,
                i: grid,
                j: rod,
                dof,
                mat,
                rayleigh: true,
                group: Some("rod_hinge".into()),
                side: None,
                member: Some("rod".into()),
            });
            id += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eigen::{modal_analysis, LanczosSettings};
    use crate::model::{Fixity, Mass};

    /// First mode (Hz) of one M8 rod of `length_mm` in `elements` beams,
    /// fixed at the top and pinned at the bottom, mass lumped as
    /// [`rod_masses`] lumps it.
    fn rod_mode_hz(elements: usize, length_mm: f64) -> f64 {
        let p = Parameters::prior_midpoints();
        let mut m = Model::empty("rod");
        let beam_t = MEMBER_KG_PER_M[3] * length_mm * 1e-6 / elements as f64;
        for k in 0..=elements {
            let z_mm = length_mm * k as f64 / elements as f64;
            m.nodes.push(Node { id: k as u64 + 1, xyz_mm: [0.0, 0.0, z_mm] });
            if k > 0 {
                push_beam(&mut m, k as u64, k as u64 + 1, section(&p), &p, [1.0, 0.0, 0.0], "rod");
            }
            if k > 0 && k < elements {
                m.masses
                    .push(Mass { node: k as u64 + 1, m_t: [beam_t, beam_t, 0.0, 0.0, 0.0, 0.0] });
            }
        }
        m.fixities.push(Fixity { node: 1, fixed: [true, true, true, false, false, true] });
        m.fixities.push(Fixity { node: elements as u64 + 1, fixed: [true; 6] });
        modal_analysis(&m, 1, &LanczosSettings::default()).unwrap().1.freq_hz[0]
    }

    /// The fixed–pinned rod's first mode, continuous: 15.418/2π · √(EI/m)/L².
    fn continuous_hz(length_mm: f64) -> f64 {
        let p = Parameters::prior_midpoints();
        let ei = p.value_or_midpoint("E") * section(&p)[2];
        let m_t_per_mm = MEMBER_KG_PER_M[3] * 1e-6;
        15.418 / (2.0 * std::f64::consts::PI) * (ei / m_t_per_mm).sqrt() / (length_mm * length_mm)
    }

    #[test]
    fn rod_mode_against_continuous_rod() {
        let exact = continuous_hz(1000.0);
        let error = |n: usize| rod_mode_hz(n, 1000.0) / exact - 1.0;
        let (two, three, four) = (error(2), error(3), error(4));
        eprintln!("continuous {exact:.3} Hz; lumped 2: {two:+.4}, 3: {three:+.4}, 4: {four:+.4}");
        assert!(three.abs() < 0.01, "three beams: {three:+.4}");
        assert!(four.abs() < three.abs() && three.abs() < two.abs(), "{two} {three} {four}");
    }
}
