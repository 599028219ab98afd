//! The perimeter (seed Table 4.5): on a semi-free wall each grid end slides
//! along its own axis against a friction spring and may pound the wall angle
//! across the gap; perpendicular and vertical restraints are 10 kN/mm. On a
//! free wall the end is unattached: the along-axis law acts across the axis
//! too (group `perimeter_friction_across`; no gap there). On a fixed wall
//! the end is held by 10 kN/mm in every direction (group `perimeter_fixed`
//! along its axis), with no friction and no gap. Which walls are which:
//! [`super::spec::Boundary::on_side`].
//!
//! Along-axis laws by `[model] perimeter`:
//! - `linear`: Elastic K_friction;
//! - `friction`: Steel01 (Fy `friction_fy_N`, E0 K_friction, b `friction_b`;
//!   seed 5.1.1: 2 N, 20 N/mm, 0.05);
//! - `pounding`: Elastic K_friction plus the eq. 5.4 Gap with gap
//!   `gap_ratio` × nominal gap and k `impact_factor` × 0.4 EA/L (588, 217,
//!   433 N/mm for main, cross and sub cross tees, seed 5.1.2); with a
//!   `gap_spread` s ≠ 0 the ends along each wall get gaps (1 + s q) × the
//!   gap, q from [`gap_offsets`];
//! - `friction-pounding`: Steel01 plus the Gap (the seed's nonlinear model).
//!
//! Each grid line's two ends take `K_friction` times the line's along factor
//! ([`super::along`]; 1 unless given).
//!
//! Materials: 1 Elastic K_friction, 2 the restraint, then Steel01 if
//! friction, then the three Gaps if pounding, then one Gap per other
//! (member, gap) pair a `gap_spread` makes and one along-axis law per other
//! line factor. Springs (ids from 100001, ends
//! in grid-node id order as the verification models number them) per end:
//! friction, gap, perpendicular, vertical; the wall node is i on the
//! x = 0 / y = 0 walls and j on the far walls, so motion towards a wall is
//! d < 0. Only the elastic springs (K_friction, restraints) enter the
//! Rayleigh term; Steel01 friction and gap springs do not, as in the
//! verification models (`ceiling_2p4_linear.json`, `_nonlinear_*.json`).
//! Units: N, mm.

use super::along::{is_along_factor, line_factor_name, row_factor_name};
use super::grid::{GenerateError, Grid, Member};
use super::params::Parameters;
use super::spec::{CeilingSpec, EndCondition};
use crate::materials::MaterialSpec;
use crate::model::{MaterialDef, Model, Node, Spring};

/// Perpendicular and vertical perimeter restraint (N/mm).
pub const RESTRAINT_N_PER_MM: f64 = 10000.0;
/// Gap contact stiffness 0.4 EA/L of main, cross and sub cross tees (N/mm, seed 5.1.2).
pub const GAP_K_N_PER_MM: [f64; 3] = [588.0, 217.0, 433.0];

/// The perimeter materials in id order (from 1).
fn materials(spec: &CeilingSpec, p: &Parameters) -> Vec<MaterialSpec> {
    let k_f = p.value_or_midpoint("K_friction");
    let per = spec.model.perimeter;
    let mut mats =
        vec![MaterialSpec::Elastic { k: k_f }, MaterialSpec::Elastic { k: RESTRAINT_N_PER_MM }];
    if per.has_friction() {
        let fy = p.value_or_midpoint("friction_fy_N");
        mats.push(MaterialSpec::Steel01 { fy, e0: k_f, b: p.value_or_midpoint("friction_b") });
    }
    if per.has_pounding() {
        let gap = p.value_or_midpoint("gap_ratio") * spec.structure.nominal_gap_mm;
        let factor = p.value_or_midpoint("impact_factor");
        mats.extend(GAP_K_N_PER_MM.map(|k| MaterialSpec::Gap { k: factor * k, gap }));
    }
    let k_across = p.value_or_midpoint("K_across");
    if k_across != RESTRAINT_N_PER_MM {
        mats.push(MaterialSpec::Elastic { k: k_across });
    }
    mats
}

/// Offsets q of the gaps of `n` grid ends along one wall, in wall order:
/// evenly spaced over (−1, 1) with mean 0, tight and wide ends alternating
/// (ranks 0, n − 1, 1, n − 2, …) so that neither half of a wall is tighter.
pub fn gap_offsets(n: usize) -> Vec<f64> {
    (0..n).map(|p| gap_offset(p, n)).collect()
}

/// The offset q of the end at position `p` of `n` along a wall ([`gap_offsets`]).
fn gap_offset(p: usize, n: usize) -> f64 {
    let rank = if p.is_multiple_of(2) { p / 2 } else { n - 1 - p / 2 };
    -1.0 + (2 * rank + 1) as f64 / n as f64
}

/// The offset q of a grid end's gap along its wall ([`gap_offsets`]).
fn end_offset(g: &Grid, end: &End) -> f64 {
    let (i, j, _, _, side, _) = *end;
    let (at, along) =
        if side.starts_with('y') { (i, g.y_line_columns()) } else { (j, g.cross_rows()) };
    let pos = along.iter().position(|&k| k == at).unwrap_or(0);
    gap_offset(pos, along.len())
}

/// The id of material `base` rescaled by `scale` (None: `base` itself, as
/// for a material `scale` does not touch): an equal material already in
/// `m`, or a new one after the others.
fn rescaled(
    m: &mut Model,
    base: u64,
    scale: impl Fn(&MaterialSpec) -> Option<MaterialSpec>,
) -> u64 {
    let Some(spec) = m.materials.iter().find(|d| d.id == base).and_then(|d| scale(&d.spec)) else {
        return base;
    };
    if let Some(d) = m.materials.iter().find(|d| d.spec == spec) {
        return d.id;
    }
    let id = m.materials.iter().map(|d| d.id).max().unwrap_or(0) + 1;
    m.materials.push(MaterialDef { id, spec });
    id
}

/// The id of the Gap material `base` with its gap times `factor`: `base`
/// itself for 1, else an equal material already in `m` or a new one.
fn scaled_gap(m: &mut Model, base: u64, factor: f64) -> u64 {
    rescaled(m, base, |spec| match spec {
        MaterialSpec::Gap { k, gap } if factor != 1.0 => {
            Some(MaterialSpec::Gap { k: *k, gap: gap * factor })
        }
        _ => None,
    })
}

/// The id of the along-axis material `base` with its stiffness times
/// `factor` (Elastic k, Steel01 E0; its yield force kept): `base` itself
/// for 1, else an equal material already in `m` or a new one.
fn scaled_along(m: &mut Model, base: u64, factor: f64) -> u64 {
    rescaled(m, base, |spec| match *spec {
        _ if factor == 1.0 => None,
        MaterialSpec::Elastic { k } => Some(MaterialSpec::Elastic { k: k * factor }),
        MaterialSpec::Steel01 { fy, e0, b } => {
            Some(MaterialSpec::Steel01 { fy, e0: e0 * factor, b })
        }
        _ => None,
    })
}

/// The along factor's name of the grid line an end belongs to: its cross-tee
/// row (an end on an x wall) or its y-line (on a y wall).
fn line_of(g: &Grid, end: &End) -> &'static str {
    let (i, j, axial, ..) = *end;
    if axial == 1 {
        row_factor_name(j as f64 * g.module_mm)
    } else {
        line_factor_name(i as f64 * g.module_mm)
    }
}

/// The factor names of the lines with an end on a wall that is not fixed,
/// each once: rows by y, then y-lines by x.
pub(super) fn sliding_lines(g: &Grid, spec: &CeilingSpec) -> Vec<&'static str> {
    let sliding = |e: &End| spec.structure.boundary.on_side(e.4) != EndCondition::Fixed;
    let mut rows: Vec<(usize, &'static str)> = vec![];
    let mut lines: Vec<(usize, &'static str)> = vec![];
    for e in ends(g).iter().filter(|e| sliding(e)) {
        let (list, at) = if e.2 == 1 { (&mut rows, e.1) } else { (&mut lines, e.0) };
        list.push((at, line_of(g, e)));
    }
    for list in [&mut rows, &mut lines] {
        list.sort_unstable();
        list.dedup();
    }
    rows.into_iter().chain(lines).map(|(_, n)| n).collect()
}

/// Refuses an along factor that names no grid line of the specimen ending
/// on a wall.
pub(super) fn check_along_factors(g: &Grid, p: &Parameters) -> Result<(), GenerateError> {
    let lines: Vec<&str> = ends(g).iter().map(|e| line_of(g, e)).collect();
    for (name, _) in p.iter().filter(|(n, _)| is_along_factor(n)) {
        if !lines.contains(&name) {
            let mut known: Vec<&str> = vec![];
            for l in &lines {
                if !known.contains(l) {
                    known.push(l);
                }
            }
            return Err(GenerateError::NoSuchLine { name: name.into(), lines: known.join(", ") });
        }
    }
    Ok(())
}

/// One grid end at the wall: grid (i, j), along-axis DOF, whether the wall
/// node is spring node i, wall side, member.
type End = (usize, usize, u8, bool, &'static str, Member);

fn ends(g: &Grid) -> Vec<End> {
    let mut ends = vec![];
    for (j, side, wall_first) in [(0, "y0", true), (g.ny, "y1", false)] {
        ends.extend(
            g.y_line_columns().into_iter().map(|i| (i, j, 2u8, wall_first, side, g.y_line(i))),
        );
    }
    for (i, side, wall_first) in [(0, "x0", true), (g.nx, "x1", false)] {
        ends.extend(
            g.cross_rows().into_iter().map(|j| (i, j, 1u8, wall_first, side, Member::Cross)),
        );
    }
    // Stable: a corner of members on the walls keeps its y-wall end first.
    ends.sort_by_key(|e| g.id(e.0, e.1));
    ends
}

/// The (dof, material, group) of each spring at one grid end whose axis is
/// `axial`: the along-axis law `friction_mat` (plus the gap `gap_mat`, if
/// any), the across-axis support `across_mat` of a semi-free end, and the
/// restraints (material 2) its wall's `condition` gives.
fn end_springs(
    condition: EndCondition,
    axial: u8,
    (friction_mat, across_mat): (u64, u64),
    gap_mat: Option<u64>,
) -> Vec<(u8, u64, &'static str)> {
    let perpendicular = if axial == 1 { 2 } else { 1 };
    let mut list = match condition {
        EndCondition::Fixed => vec![(axial, 2, "perimeter_fixed")],
        _ => vec![(axial, friction_mat, "perimeter_friction")],
    };
    if let (Some(gap), false) = (gap_mat, condition == EndCondition::Fixed) {
        list.push((axial, gap, "perimeter_gap"));
    }
    list.push(match condition {
        EndCondition::Free => (perpendicular, friction_mat, "perimeter_friction_across"),
        EndCondition::Fixed => (perpendicular, 2, "perimeter_perpendicular"),
        _ => (perpendicular, across_mat, "perimeter_perpendicular"),
    });
    list.push((3, 2, "perimeter_vertical"));
    list
}

/// Materials, wall nodes and springs of the perimeter; returns the wall nodes.
pub(super) fn perimeter(g: &Grid, spec: &CeilingSpec, p: &Parameters, m: &mut Model) -> Vec<Node> {
    m.materials = materials(spec, p)
        .into_iter()
        .enumerate()
        .map(|(k, spec)| MaterialDef { id: k as u64 + 1, spec })
        .collect();
    let per = spec.model.perimeter;
    let friction_mat = if per.has_friction() { 3 } else { 1 };
    let first_gap = 3 + u64::from(per.has_friction());
    let spread = if per.has_pounding() { p.value_or_midpoint("gap_spread") } else { 0.0 };
    // The across-axis material: the restraint (2), or the last of `materials`.
    let across_mat = if p.value_or_midpoint("K_across") == RESTRAINT_N_PER_MM {
        2
    } else {
        m.materials.len() as u64
    };
    let mut walls = vec![];
    for end in ends(g) {
        let (i, j, axial, wall_first, side, member) = end;
        let grid = g.id(i, j);
        let wall = 100000 + grid;
        let xyz_mm = [i as f64 * g.module_mm, j as f64 * g.module_mm, 0.0];
        // A corner's two ends (members on the walls) share its wall node.
        if walls.last().is_none_or(|n: &Node| n.id != wall) {
            walls.push(Node { id: wall, xyz_mm });
        }
        let (a, b) = if wall_first { (wall, grid) } else { (grid, wall) };
        let factor = 1.0 + spread * end_offset(g, &end);
        let gap_mat = per.has_pounding().then(|| scaled_gap(m, first_gap + member.index(), factor));
        let along_mat = match p.get(line_of(g, &end)) {
            f if f.is_nan() => friction_mat,
            f => scaled_along(m, friction_mat, f),
        };
        let condition = spec.structure.boundary.on_side(side);
        let list = end_springs(condition, axial, (along_mat, across_mat), gap_mat);
        for (dof, mat, group) in list {
            // The along law enters the Rayleigh term where it is elastic.
            let base = if mat == along_mat { friction_mat } else { mat };
            m.springs.push(Spring {
                id: 100001 + m.springs.len() as u64,
                i: a,
                j: b,
                dof,
                mat,
                rayleigh: base == 1 || base == 2 || base == across_mat,
                group: Some(group.into()),
                side: Some(side.into()),
                member: Some(member.name().into()),
            });
        }
    }
    walls
}

#[cfg(test)]
mod tests {
    use super::gap_offsets;
    use proptest::prelude::*;

    #[test]
    fn five_ends_alternate_tight_and_wide() {
        let q = gap_offsets(5);
        let expected = [-0.8, 0.8, -0.4, 0.4, 0.0];
        assert!(q.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-12), "{q:?}");
    }

    proptest! {
        #[test]
        fn offsets_are_an_even_spread_with_mean_zero(n in 1usize..40) {
            let mut q = gap_offsets(n);
            let mean = q.iter().sum::<f64>() / n as f64;
            prop_assert!(mean.abs() < 1e-12);
            q.sort_by(f64::total_cmp);
            for (k, v) in q.iter().enumerate() {
                prop_assert!((v - (-1.0 + (2 * k + 1) as f64 / n as f64)).abs() < 1e-12);
            }
        }
    }
}
