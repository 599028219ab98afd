//! The grid builder: nodes on the module grid (room corners dropped unless
//! members lie on the walls), main tees and sub cross tees along y, cross
//! tees along x (on the wall lines too with `wall_members`), hanger rods
//! fixed at the top ([`super::rods`]), the semi-free perimeter ([`super::perimeter`]), the grid
//! connections ([`super::connections`], none when rigid) and panel masses
//! lumped a quarter to each panel corner.
//!
//! Numbering (the verification generator's scheme, so that generated files
//! compare one to one): grid node (i, j) at (i·module, j·module, 0) has id
//! 1 + i + (nx + 1)·j; its wall node 100000 + id; rod top 200000 + id (the
//! rods' own nodes: [`super::rods`]); beams
//! from 1 (y-lines, cross tees, rods); perimeter springs from 100001;
//! connection nodes from 300000 + id and their springs from 300001.
//!
//! Sections (seed Table 4.4, Table 6.1 names): main tee A_main, J_main,
//! Iy_main, Iz 1000 mm⁴; cross tee A_cross, J_cross, Iy_cross, Iz_cross; sub
//! cross tee 28 mm², J 4200, Iy 3000, Iz 650; rod M8 40 mm², I = A²/4π,
//! J = 2I. With `connections = "rigid"` the members are continuous through
//! the joints and the model is numbered exactly as above; the double layer's
//! carrying channels are modelled only when given (their mass at the rod
//! nodes, their beams between them, numbered after every other beam; the
//! rods end at the main tees).

use serde_json::json;

use super::connections::connections;
use super::params::{parameters_for, ParamError, Parameters, MEMBER_KG_PER_M};
use super::perimeter::{check_along_factors, perimeter, sliding_lines};
use super::rods::{rod_hinges, rod_masses, rods, Rods};
use super::spec::{CeilingSpec, Structure};
use crate::model::{validate, Analysis, Beam, Fixity, Mass, Model, ModelError, Node};

/// Why a model could not be generated.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// The generated model broke a rule of the format (a generator bug).
    #[error("generated model is invalid: {0}")]
    Invalid(#[from] ModelError),
    /// A parameter value given that the specimen's model variant does not use.
    #[error(transparent)]
    Parameter(#[from] ParamError),
    /// An along factor naming a grid line the specimen does not have.
    #[error("parameter `{name}`: no grid line of this specimen ends on a wall there (its lines: {lines})")]
    NoSuchLine {
        /// The parameter's name.
        name: String,
        /// The specimen's lines' factor names.
        lines: String,
    },
}

/// Member kinds of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Member {
    Main,
    Cross,
    Sub,
}

impl Member {
    /// Group name of its beams.
    pub(super) fn name(self) -> &'static str {
        match self {
            Member::Main => "main_tee",
            Member::Cross => "cross_tee",
            Member::Sub => "sub_cross_tee",
        }
    }
    /// Position in (main, cross, sub) order.
    pub(super) fn index(self) -> u64 {
        match self {
            Member::Main => 0,
            Member::Cross => 1,
            Member::Sub => 2,
        }
    }
}

/// Grid geometry in module counts.
pub(super) struct Grid {
    /// Modules along x.
    pub(super) nx: usize,
    /// Modules along y.
    pub(super) ny: usize,
    /// Module (mm).
    pub(super) module_mm: f64,
    main_every: usize,
    rod_every: usize,
    /// Column of the first main tee and row of the first rods, modulo
    /// their spacing (0: lines from the origin; 1: one module in).
    phase: usize,
    /// Whether members lie on the wall lines ([`super::spec::Structure::wall_members`]).
    pub(super) wall_members: bool,
    /// Row of the first rods modulo their spacing (`phase` moved by the
    /// hanger offset's modules).
    rod_phase: usize,
}

impl Grid {
    /// Id of grid node (i, j).
    pub(super) fn id(&self, i: usize, j: usize) -> u64 {
        (1 + i + (self.nx + 1) * j) as u64
    }
    fn exists(&self, i: usize, j: usize) -> bool {
        let edge_x = i == 0 || i == self.nx;
        let edge_y = j == 0 || j == self.ny;
        self.wall_members || !(edge_x && edge_y)
    }
    /// Whether a member runs along y-line i (0 <= i <= nx): every line
    /// between the walls; a wall's line when members lie on the walls and
    /// it is a main-tee line.
    pub(super) fn has_y_line(&self, i: usize) -> bool {
        let wall = i == 0 || i == self.nx;
        !wall || (self.wall_members && self.y_line(i) == Member::Main)
    }
    /// The y-lines that carry a member, ascending.
    pub(super) fn y_line_columns(&self) -> Vec<usize> {
        (0..=self.nx).filter(|&i| self.has_y_line(i)).collect()
    }
    /// The rows (0 <= j <= ny) that carry a cross tee, ascending.
    pub(super) fn cross_rows(&self) -> Vec<usize> {
        (0..=self.ny).filter(|&j| (j != 0 && j != self.ny) || self.wall_members).collect()
    }
    /// The rows (0 < j < ny) that carry hanger rods, ascending: every
    /// `rod_every`-th from the hanger offset.
    pub(super) fn rod_rows(&self) -> Vec<usize> {
        (1..self.ny)
            .filter(|j| (j + self.rod_every - self.rod_phase).is_multiple_of(self.rod_every))
            .collect()
    }
    /// The member along y-line i, if it carries one ([`Grid::has_y_line`]).
    pub(super) fn y_line(&self, i: usize) -> Member {
        if (i + self.main_every - self.phase).is_multiple_of(self.main_every) {
            Member::Main
        } else {
            Member::Sub
        }
    }
}

/// Builds the model of a specimen with the given parameter values; a
/// parameter the variant uses and `params` lacks takes its prior mid-point
/// (the seed's value for the extension parameters); a value for a parameter
/// the variant does not use is refused.
pub fn generate(spec: &CeilingSpec, params: &Parameters) -> Result<Model, GenerateError> {
    check_used(spec, params)?;
    let s = &spec.structure;
    let g = grid_of(s);
    check_along_factors(&g, params)?;
    let mut m = empty(spec);
    grid_nodes(&g, &mut m);
    y_lines(&g, params, &mut m);
    cross_tees(&g, params, &mut m);
    let rods = rods(&g, params, s.hanger_length_m * 1000.0, &mut m);
    let rod_tops = &rods.tops;
    let walls = perimeter(&g, spec, params, &mut m);
    let pieces = connections(&g, spec, params, &mut m);
    rod_hinges(&rods, params, &mut m);
    masses(&g, s.panel_mass_kg * 1e-3 * params.value_or_midpoint("panel_mass_factor"), &mut m);
    member_masses(&g, &rods, params.value_or_midpoint("member_mass_factor"), &mut m);
    if s.layers == 2 {
        let kg_per_m = params.value_or_midpoint("channel_mass_kg_per_m");
        channel_masses(rod_tops, s.length_x_m, kg_per_m, &mut m);
        channel_beams(rod_tops, params, &mut m);
    }
    m.nodes.extend(walls.iter().chain(rod_tops).chain(&pieces).copied());
    m.fixities =
        walls.iter().chain(rod_tops).map(|n| Fixity { node: n.id, fixed: [true; 6] }).collect();
    m.meta = Some(meta(spec, params, &g, &m));
    validate(&m)?;
    Ok(m)
}

/// The grid geometry of a structure in module counts.
fn grid_of(s: &Structure) -> Grid {
    let ratio = |a: f64| (a / s.module_m).round() as usize;
    Grid {
        nx: ratio(s.length_x_m),
        ny: ratio(s.length_y_m),
        module_mm: s.module_m * 1000.0,
        main_every: ratio(s.main_tee_spacing_m).max(1),
        rod_every: ratio(s.hanger_spacing_m).max(1),
        phase: usize::from(!s.lines_from_origin),
        wall_members: s.wall_members,
        rod_phase: (usize::from(!s.lines_from_origin) + ratio(s.hanger_offset_m))
            % ratio(s.hanger_spacing_m).max(1),
    }
}

/// The along factors ([`super::along`]) of the specimen's grid lines that
/// end on a wall their ends may slide along (not a fixed wall), rows first
/// by y, then y-lines by x.
pub fn along_factor_names(spec: &CeilingSpec) -> Vec<&'static str> {
    sliding_lines(&grid_of(&spec.structure), spec)
}

/// Refuses values of parameters the specimen's variant does not use.
fn check_used(spec: &CeilingSpec, params: &Parameters) -> Result<(), ParamError> {
    let used = parameters_for(spec);
    let mut probe = Parameters::prior_midpoints_for(spec);
    for (name, value) in params.iter() {
        if !used.iter().any(|p| p.name == name) {
            probe.set(name, value)?;
        }
    }
    Ok(())
}

fn empty(spec: &CeilingSpec) -> Model {
    let s = &spec.structure;
    Model {
        description: format!(
            "Suspended-ceiling grid {} m x {} m, module {} m, {} perimeter; generated by ceilfarm fe mesh",
            s.length_x_m,
            s.length_y_m,
            s.module_m,
            s.boundary.as_str()
        ),
        analysis: Some(Analysis::Eigen { n_modes: 12, extra: Default::default() }),
        ..Model::empty(&format!("ceiling_{}x{}", s.length_x_m, s.length_y_m))
    }
}

fn grid_nodes(g: &Grid, m: &mut Model) {
    for j in 0..=g.ny {
        for i in 0..=g.nx {
            if g.exists(i, j) {
                let xyz_mm = [i as f64 * g.module_mm, j as f64 * g.module_mm, 0.0];
                m.nodes.push(Node { id: g.id(i, j), xyz_mm });
            }
        }
    }
}

/// Section (A, J, Iy, Iz) of a member from the parameters, the area times
/// `grid_axial_factor` and the inertias times `grid_bending_factor`.
fn section(member: Member, p: &Parameters) -> [f64; 4] {
    let v = |name| p.value_or_midpoint(name);
    let [a, j, iy, iz] = match member {
        Member::Main => [v("A_main"), v("J_main"), v("Iy_main"), 1000.0],
        Member::Cross => [v("A_cross"), v("J_cross"), v("Iy_cross"), v("Iz_cross")],
        Member::Sub => [28.0, 4200.0, 3000.0, 650.0],
    };
    let (fa, fb) = (v("grid_axial_factor"), v("grid_bending_factor"));
    [a * fa, j * fb, iy * fb, iz * fb]
}

pub(super) fn push_beam(
    m: &mut Model,
    i: u64,
    j: u64,
    sec: [f64; 4],
    p: &Parameters,
    vecxz: [f64; 3],
    group: &str,
) {
    let id = m.beams.len() as u64 + 1;
    m.beams.push(Beam {
        id,
        i,
        j,
        area_mm2: sec[0],
        e_mpa: p.value_or_midpoint("E"),
        g_mpa: p.value_or_midpoint("G"),
        j_mm4: sec[1],
        iy_mm4: sec[2],
        iz_mm4: sec[3],
        vecxz,
        group: Some(group.into()),
    });
}

fn y_lines(g: &Grid, p: &Parameters, m: &mut Model) {
    for i in g.y_line_columns() {
        let member = g.y_line(i);
        for j in 0..g.ny {
            push_beam(
                m,
                g.id(i, j),
                g.id(i, j + 1),
                section(member, p),
                p,
                [0.0, 0.0, 1.0],
                member.name(),
            );
        }
    }
}

fn cross_tees(g: &Grid, p: &Parameters, m: &mut Model) {
    for j in g.cross_rows() {
        for i in 0..g.nx {
            let sec = section(Member::Cross, p);
            push_beam(m, g.id(i, j), g.id(i + 1, j), sec, p, [0.0, 0.0, 1.0], "cross_tee");
        }
    }
}

/// The carrying channels' mass, `kg_per_m` along x over the plan's length
/// `length_x_m` through every row of rods, shared evenly among the row's
/// rod nodes (the bottom nodes of `rod_tops`), added to their mass (t).
fn channel_masses(rod_tops: &[Node], length_x_m: f64, kg_per_m: f64, m: &mut Model) {
    if kg_per_m <= 0.0 {
        return;
    }
    let row_of = |n: &Node| n.xyz_mm[1].to_bits();
    for top in rod_tops {
        let in_row = rod_tops.iter().filter(|n| row_of(n) == row_of(top)).count();
        let t = kg_per_m * length_x_m * 1e-3 / in_row as f64;
        let node = top.id - 200000;
        match m.masses.iter_mut().find(|x| x.node == node) {
            Some(x) => x.m_t.iter_mut().take(3).for_each(|v| *v += t),
            None => m.masses.push(Mass { node, m_t: [t, t, t, 0.0, 0.0, 0.0] }),
        }
    }
}

/// The seed's carrying channel U50x15x1: A, J, Iy (vertical bending, web
/// vertical), Iz (mm², mm⁴).
const CHANNEL_SECTION: [f64; 4] = [70.0, 27.0, 2.9e4, 1.6e3];

/// The carrying channels' beams along x between neighbouring rod nodes of
/// each row, the section [`CHANNEL_SECTION`] times `channel_beam_factor`
/// (none at 0).
fn channel_beams(rod_tops: &[Node], p: &Parameters, m: &mut Model) {
    let factor = p.value_or_midpoint("channel_beam_factor");
    if factor <= 0.0 {
        return;
    }
    let sec = CHANNEL_SECTION.map(|v| v * factor);
    let row_of = |n: &Node| n.xyz_mm[1].to_bits();
    for (k, a) in rod_tops.iter().enumerate() {
        let next = rod_tops[k + 1..].iter().filter(|b| row_of(b) == row_of(a));
        if let Some(b) = next.min_by(|u, v| u.xyz_mm[0].total_cmp(&v.xyz_mm[0])) {
            if b.xyz_mm[0] > a.xyz_mm[0] {
                push_beam(
                    m,
                    a.id - 200000,
                    b.id - 200000,
                    sec,
                    p,
                    [0.0, 0.0, 1.0],
                    "carrying_channel",
                );
            }
        }
    }
}

/// The members' own mass ([`MEMBER_KG_PER_M`] times `factor`): each grid
/// segment's half on each of its grid nodes, and the rods' along them
/// ([`rod_masses`]); none at 0.
fn member_masses(g: &Grid, rods: &Rods, factor: f64, m: &mut Model) {
    if factor <= 0.0 {
        return;
    }
    let segment_t = |member: Member| MEMBER_KG_PER_M[member.index() as usize] * g.module_mm * 1e-6;
    let mut add = |node: u64, t: [f64; 3]| match m.masses.iter_mut().find(|x| x.node == node) {
        Some(x) => x.m_t.iter_mut().zip(t).for_each(|(v, t)| *v += t),
        None => m.masses.push(Mass { node, m_t: [t[0], t[1], t[2], 0.0, 0.0, 0.0] }),
    };
    for i in g.y_line_columns() {
        let t = 0.5 * factor * segment_t(g.y_line(i));
        for j in 0..g.ny {
            add(g.id(i, j), [t; 3]);
            add(g.id(i, j + 1), [t; 3]);
        }
    }
    let t = 0.5 * factor * segment_t(Member::Cross);
    for j in g.cross_rows() {
        for i in 0..g.nx {
            add(g.id(i, j), [t; 3]);
            add(g.id(i + 1, j), [t; 3]);
        }
    }
    for (node, t) in rod_masses(rods, factor) {
        add(node, t);
    }
}

/// A quarter of each panel's mass on each existing corner node (t).
fn masses(g: &Grid, panel_t: f64, m: &mut Model) {
    let mut node_t = vec![0.0; (g.nx + 1) * (g.ny + 1)];
    for j in 0..g.ny {
        for i in 0..g.nx {
            for (a, b) in [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)] {
                if g.exists(a, b) {
                    node_t[a + (g.nx + 1) * b] += 0.25 * panel_t;
                }
            }
        }
    }
    for j in 0..=g.ny {
        for i in 0..=g.nx {
            let t = node_t[i + (g.nx + 1) * j];
            if t > 0.0 {
                m.masses.push(Mass { node: g.id(i, j), m_t: [t, t, t, 0.0, 0.0, 0.0] });
            }
        }
    }
}

fn meta(spec: &CeilingSpec, p: &Parameters, g: &Grid, m: &Model) -> serde_json::Value {
    let params: serde_json::Map<String, serde_json::Value> =
        p.iter().map(|(k, v)| (k.to_string(), json!(v))).collect();
    let defaulted: serde_json::Map<String, serde_json::Value> = parameters_for(spec)
        .iter()
        .filter(|i| p.get(i.name).is_nan())
        .map(|i| (i.name.to_string(), json!(i.default_value())))
        .collect();
    let model = spec.model;
    let mut notes = vec![if model.connections == super::spec::Connections::Rigid {
        "grid connections continuous (rigid); K_rod, K_cc1-3, K_mc not modelled"
    } else {
        "grid connections as zero-length springs (K_cc1-3 tee joints, K_mc splices); K_rod not modelled"
    }];
    if spec.structure.layers == 2 {
        let mass = p.value_or_midpoint("channel_mass_kg_per_m") > 0.0;
        let beams = p.value_or_midpoint("channel_beam_factor") > 0.0;
        notes.push(match (mass, beams) {
            (false, false) => "layers = 2: carrying channels not modelled; rods end at the main tees",
            (true, false) => "layers = 2: carrying channels as mass at the rod nodes (channel_mass_kg_per_m), their stiffness not modelled; rods end at the main tees",
            (false, true) => "layers = 2: carrying channels as beams between the rod nodes (channel_beam_factor), their mass not modelled; rods end at the main tees",
            (true, true) => "layers = 2: carrying channels as mass at the rod nodes (channel_mass_kg_per_m) and beams between them (channel_beam_factor); rods end at the main tees",
        });
    }
    let variant = match (model.perimeter, model.connections) {
        (super::spec::Perimeter::Linear, super::spec::Connections::Rigid) => "linear",
        (super::spec::Perimeter::FrictionPounding, super::spec::Connections::Rigid) => "nonlinear",
        _ => "extended",
    };
    let mut meta = json!({
        "generator": "ceilfarm fe mesh",
        "Lx": g.nx as f64 * g.module_mm, "Ly": g.ny as f64 * g.module_mm, "module": g.module_mm,
        "nx_modules": g.nx, "ny_modules": g.ny,
        "variant": variant,
        "perimeter": model.perimeter.name(),
        "connections": model.connections.name(),
        "layers": spec.structure.layers,
        "parameters": params,
        "parameters_at_midpoint": defaulted,
        "n_nodes": m.nodes.len(), "n_beams": m.beams.len(), "n_springs": m.springs.len(),
        "mass_total_t": m.masses.iter().map(|x| x.m_t[0]).sum::<f64>(),
        "notes": notes,
    });
    if g.wall_members {
        meta["wall_members"] = json!(true);
    }
    meta
}
