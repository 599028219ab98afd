"""Second truth-model family for the diagnosis bench (OpenSeesPy; N, mm, s, tonne).

Written from the physical description (shared/spec/seed-facts.md,
shared/spec/measured-bundle.md) only, apart from the project's own model
generator. A rectangular single-layer suspended-ceiling grid:

* main tees along y at x = 0, 1.2, 2.4, ... (continuous, spliced every 3.6 m
  when connections are springs), cross tees along x one every 0.6 m in y
  (1.2 m pieces between main tees, cut pieces to a wall in a half bay),
  sub cross tees along y at the mid-line between main tees (0.6 m pieces);
* hanger rods (beams, fixed at the top) on a 1.2 m grid on the main tees,
  pinned to the tee or held by a rotational spring;
* panel mass lumped at the grid nodes (each panel a quarter to each corner);
* perimeter: every grid end on a wall angle gets a spring along the member's
  axis, one across it and a stiff vertical support; corners get the two
  along-springs of the two members ending there.

Every random modelling choice is drawn by `draw_truth` into a plain dict (which
goes into truth.json); `Model` builds OpenSees from that dict plus an optional
hidden effect; `Model.simulate` integrates one base-acceleration record.
"""

import math

import numpy as np
import openseespy.opensees as ops

MOD = 600.0  # mm, module
S_MAIN = 1200.0  # mm, main tee spacing
G_MM = 9806.65  # mm/s2


class SimulationError(RuntimeError):
    pass


def logu(rng, a, b):
    return float(math.exp(rng.uniform(math.log(a), math.log(b))))


def u(rng, a, b):
    return float(rng.uniform(a, b))


# ----------------------------------------------------------------------------
# geometry (pure Python, no OpenSees): nodes, members, perimeter ends, joints
# ----------------------------------------------------------------------------
class Grid:
    """Topology of an nx x ny module grid. Grid node (i, j) is at (0.6 i, 0.6 j) m."""

    def __init__(self, lx_m, ly_m):
        self.nx = int(round(lx_m / 0.6))
        self.ny = int(round(ly_m / 0.6))
        nx, ny = self.nx, self.ny
        self.main_cols = [i for i in range(0, nx + 1, 2)]
        self.sub_cols = [i for i in range(1, nx, 2)]  # a mid-line between two main tees
        # cross-tee pieces per row: (a, b) column range; b is a main tee or the wall
        self.cross_pieces = []
        for a in self.main_cols:
            if a + 2 <= nx:
                self.cross_pieces.append((a, a + 2))
            elif a + 1 == nx:
                self.cross_pieces.append((a, a + 1))  # cut piece to the wall at x = Lx
        # perimeter ends: (i, j, axis, sign) axis 0 = x, 1 = y; sign -1 low wall, +1 high wall
        self.ends = []
        for i in range(nx + 1):
            for j in range(ny + 1):
                if i in (0, nx) and 0 < j < ny:
                    self.ends.append((i, j, 0, -1 if i == 0 else 1))
                if j in (0, ny) and 0 < i < nx:
                    self.ends.append((i, j, 1, -1 if j == 0 else 1))
                if i in (0, nx) and j in (0, ny):
                    self.ends.append((i, j, 0, -1 if i == 0 else 1))
                    self.ends.append((i, j, 1, -1 if j == 0 else 1))

    def boundary(self, i, j):
        return i in (0, self.nx) or j in (0, self.ny)

    def corner(self, i, j):
        return i in (0, self.nx) and j in (0, self.ny)

    def main_cross_joints(self):
        """(i, j, side) for every cross-tee end that meets a main tee; side +1: the
        piece runs to +x from the main tee, -1: to -x."""
        out = []
        for j in range(self.ny + 1):
            for a, b in self.cross_pieces:
                out.append((a, j, +1))
                if b in self.main_cols:
                    out.append((b, j, -1))
        return out

    def sub_joints(self):
        out = []
        for i in self.sub_cols:
            for j in range(self.ny):
                out.append((i, j, +1))
                out.append((i, j + 1, -1))
        return out


# ----------------------------------------------------------------------------
# random modelling choices
# ----------------------------------------------------------------------------
def draw_truth(rng, lx_m, ly_m, force_springs=False):
    """All modelling choices of one campaign's truth, as a JSON-ready dict."""
    g = Grid(lx_m, ly_m)
    t = {"plan_m": [lx_m, ly_m], "nx": g.nx, "ny": g.ny}
    sec = {
        "E": u(rng, 1.9e5, 2.3e5),
        "G": u(rng, 7.4e4, 8.2e4),
        "cross": {"A": u(rng, 30, 36), "J": u(rng, 4800, 5100), "Iy": u(rng, 4000, 4700), "Iz": u(rng, 650, 750)},
        "main": {"A": u(rng, 35, 42), "J": u(rng, 7900, 8500), "Iy": u(rng, 7250, 7800),
                 "Iz": u(rng, 1000, 1400)},  # Iz_main (in-plane bending) is not in Table 6.1: own range
        # sub cross tee T30x24: not in Table 6.1; own ranges scaled down from the cross tee
        "sub": {"A": u(rng, 24, 30), "J": u(rng, 3500, 4200), "Iy": u(rng, 2400, 3200), "Iz": u(rng, 550, 700)},
    }
    rod_A = 40.0 * u(rng, 0.9, 1.1)
    d = math.sqrt(4 * rod_A / math.pi)
    sec["rod"] = {"A": rod_A, "Iy": math.pi * d**4 / 64, "Iz": math.pi * d**4 / 64, "J": math.pi * d**4 / 32}
    t["sections"] = sec
    t["member_mass_kg_per_m"] = {
        "main": 1.07 * u(rng, 0.8, 1.2), "cross": 0.31 * u(rng, 0.8, 1.2),
        "sub": 0.13 * u(rng, 0.8, 1.2), "rod": 0.37 * u(rng, 0.8, 1.2)}
    # consistent mass triples OpenSees' cost per step: drawn less often
    t["member_mass_form"] = str(rng.choice(["element-consistent", "element-lumped", "grid-node-lumped"],
                                           p=[0.2, 0.4, 0.4]))
    t["panel_mass_kg"] = 1.2 * u(rng, 0.8, 1.2)
    t["panel_scatter"] = u(rng, 0.0, 0.08)
    t["panel_factors"] = [float(1 + t["panel_scatter"] * rng.uniform(-1, 1)) for _ in range(g.nx * g.ny)]
    t["connections"] = str(rng.choice(["springs", "shared-nodes"]))  # drawn always: same stream
    if force_springs:
        t["connections"] = "springs"
    # connection springs (N/mm, N mm/rad); K_cc1..3 and K_mc from Table 6.1
    t["joint_main_cross"] = {
        "axial": u(rng, 750, 850), "transverse": u(rng, 75, 125), "vertical": u(rng, 10, 35),
        "torsion": logu(rng, 1e4, 1e6), "bend_vertical": logu(rng, 1e4, 1e6), "bend_plan": logu(rng, 1e3, 1e5)}
    t["joint_sub"] = {
        "axial": logu(rng, 300, 1500), "transverse": logu(rng, 40, 200), "vertical": logu(rng, 10, 60),
        "torsion": logu(rng, 1e4, 1e6), "bend_vertical": logu(rng, 1e4, 1e6), "bend_plan": logu(rng, 1e3, 1e5)}
    t["joint_scatter"] = u(rng, 0.0, 0.15)
    t["splice"] = {"axial": u(rng, 1400, 1600), "transverse": logu(rng, 500, 5000), "vertical": 1e4,
                   "rot": logu(rng, 1e5, 1e7),
                   "offsets_m": [float(0.6 * rng.integers(1, 7)) for _ in g.main_cols]}
    t["rod_length_mm"] = 1000.0 * u(rng, 0.95, 1.05)
    t["rod_length_scatter"] = u(rng, 0.0, 0.03)
    t["rod_elements"] = int(rng.integers(1, 4))
    t["rod_first_row_m"] = float(rng.choice([0.6, 1.2]))
    t["rod_top"] = "rod_pinned" if rng.random() < 0.4 else "rod_spring"
    t["rod_rot_spring"] = logu(rng, 1e3, 1e6)  # N mm/rad, at the tee (rod_spring only)
    t["perimeter"] = {
        "K_along": u(rng, 8, 40), "K_across": logu(rng, 20, 5000), "K_vertical": logu(rng, 2000, 20000),
        "along_scatter": u(rng, 0.0, 0.2), "across_scatter": u(rng, 0.0, 0.3)}
    ne = len(g.ends)
    t["perimeter"]["along_factors"] = [float(1 + t["perimeter"]["along_scatter"] * rng.uniform(-1, 1)) for _ in range(ne)]
    t["perimeter"]["across_factors"] = [float(1 + t["perimeter"]["across_scatter"] * rng.uniform(-1, 1)) for _ in range(ne)]
    t["joint_seed"] = int(rng.integers(1, 2**31))
    t["rod_seed"] = int(rng.integers(1, 2**31))
    t["damping"] = {"zeta": u(rng, 0.02, 0.06), "anchor_first": int(rng.integers(1, 4)),
                    "anchor_gap": int(rng.integers(1, 6)),
                    "tangent": str(rng.choice(["initial", "committed"]))}
    t["integration"] = {"scheme": "Newmark average acceleration"}
    return t


def draw_effect_shape(rng, effect):
    """The hidden effect's form (its strength is set later, from the response)."""
    if effect == "perimeter-pounding":
        return {"law": str(rng.choice(["impact-bilinear", "elastic-gap"])),
                "k_contact": logu(rng, 150, 1500), "k2_ratio": u(rng, 0.3, 0.5),
                "yield_disp": u(rng, 0.05, 0.3), "gap_scatter": u(rng, 0.05, 0.3)}
    if effect == "perimeter-friction":
        return {"law": str(rng.choice(["steel01", "steel02-rounded"])), "hardening": u(rng, 0.005, 0.05),
                "R0": u(rng, 8, 20), "slip_scatter": u(rng, 0.05, 0.3)}
    if effect == "connection-hysteresis":
        return {"law": str(rng.choice(["pinching4", "hysteretic"])),
                "r2": u(rng, 1.3, 2.0), "a2": u(rng, 0.04, 0.15), "r3": u(rng, 1.05, 1.3), "a3": u(rng, 0.01, 0.05),
                "neg_ratio": u(rng, 0.9, 1.4), "rDisp": u(rng, 0.3, 0.7), "rForce": u(rng, 0.1, 0.4),
                "uForce": u(rng, -0.15, 0.05), "gK1": u(rng, 0.0, 0.2), "pinchX": u(rng, 0.3, 0.8),
                "pinchY": u(rng, 0.1, 0.5), "beta": u(rng, 0.0, 0.3), "yield_scatter": u(rng, 0.05, 0.3)}
    return {}


# ----------------------------------------------------------------------------
# OpenSees model
# ----------------------------------------------------------------------------
class Model:
    """Builds the truth in OpenSees. `effect` is None (linear truth), one hidden
    effect {"cause": ..., "shape": {...}, "per_end": [...] or "per_joint": {...}},
    or several at once {"cause": "a+b", "parts": [one such dict per effect]}.
    Pounding and friction together act in parallel at each perimeter end: the
    along spring slips (friction) and the contact closes (pounding) on the same
    end-to-wall displacement."""

    log_path = None

    def __init__(self, truth, effect=None):
        self.t = truth
        self.effect = effect
        # the hidden effects by name (one, several or none)
        self.effects = {p["cause"]: p for p in (effect.get("parts") or [effect])} if effect else {}
        self.g = Grid(*truth["plan_m"])
        self._tag = 0
        self._mat = 0
        self.node_mass = {}  # tributary translational mass, for mode classification
        ops.wipe()
        if Model.log_path:
            ops.logFile(Model.log_path, "-noEcho")  # OpenSees' own warnings go there, not to stderr
        ops.model("basic", "-ndm", 3, "-ndf", 6)
        self._build()

    def _new_node(self, x, y, z=0.0):
        self._tag += 1
        ops.node(self._tag, x, y, z)
        self.node_mass[self._tag] = 0.0
        return self._tag

    def _elastic(self, k):
        self._mat += 1
        ops.uniaxialMaterial("Elastic", self._mat, float(k))
        return self._mat

    def _add_mass(self, node, m):
        self.node_mass[node] = self.node_mass.get(node, 0.0) + m

    def _build(self):
        t, g = self.t, self.g
        sec = t["sections"]
        E, G = sec["E"], sec["G"]
        springs = t["connections"] == "springs"
        mform = t["member_mass_form"]
        self._etag = 0
        # transforms: 1 horizontal members (local z vertical), 2 rods
        ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0)
        ops.geomTransf("Linear", 2, 1.0, 0.0, 0.0)
        self.grid = {}
        for i in range(g.nx + 1):
            for j in range(g.ny + 1):
                self.grid[(i, j)] = self._new_node(i * MOD, j * MOD)
        gridnode_of = {v: k for k, v in self.grid.items()}
        self.beam_groups = {"main": [], "cross": [], "sub": [], "rod": []}

        def beam(n1, n2, kind):
            s = sec[kind]
            rho = t["member_mass_kg_per_m"][kind] * 1e-6  # kg/m -> t/mm
            self._etag += 1
            args = [self._etag, n1, n2, s["A"], E, G, s["J"], s["Iy"], s["Iz"], 2 if kind == "rod" else 1]
            c1, c2 = ops.nodeCoord(n1), ops.nodeCoord(n2)
            length = math.dist(c1, c2)
            if mform == "element-consistent":
                ops.element("elasticBeamColumn", *args, "-mass", rho, "-cMass")
            elif mform == "element-lumped":
                ops.element("elasticBeamColumn", *args, "-mass", rho)
            else:
                ops.element("elasticBeamColumn", *args)
            m = rho * length
            # tributary bookkeeping (and the actual nodal mass for grid-node-lumped)
            for n in (n1, n2):
                target = n
                if mform == "grid-node-lumped":
                    target = self._home.get(n, n)
                    if kind == "rod" and target not in gridnode_of:
                        target = self._rod_home.get(n, None)
                        if target is None:
                            continue  # the fixed top node: its half goes to the support
                self._add_mass(target, m / 2)
            self.beam_groups[kind].append(self._etag)

        self._home = {}  # own end nodes -> their grid node
        self._rod_home = {}
        self.joints = []  # dicts: kind, i, j, side, ele, dirs

        def joint(kind, i, j, side, k):
            """Own end node at grid node (i, j) joined by a 6-direction spring."""
            gn = self.grid[(i, j)]
            x, y, _ = ops.nodeCoord(gn)
            n = self._new_node(x, y)
            self._home[n] = gn
            sc = 1 + t["joint_scatter"] * self._jrng.uniform(-1, 1)
            if kind == "main-cross":  # cross tee along x
                kk = [k["axial"], k["transverse"], k["vertical"], k["torsion"], k["bend_vertical"], k["bend_plan"]]
            else:  # sub tee along y: dir 1 (x) transverse, dir 2 (y) axial, dir 4 bending about x
                kk = [k["transverse"], k["axial"], k["vertical"], k["bend_vertical"], k["torsion"], k["bend_plan"]]
            mats = [self._elastic(v * sc) for v in kk]
            rec = {"kind": kind, "i": i, "j": j, "side": side, "node": n, "grid": gn, "k": [v * sc for v in kk]}
            if kind == "main-cross" and "connection-hysteresis" in self.effects:
                idx = len([q for q in self.joints if q["kind"] == "main-cross"])
                for d in (0, 1):
                    f1 = self.effects["connection-hysteresis"]["per_joint"][d][idx]
                    mats[d] = self._hysteretic(rec["k"][d], f1)
                    rec.setdefault("yield", [None, None])[d] = f1
            self._etag += 1
            ops.element("zeroLength", self._etag, gn, n, "-mat", *mats, "-dir", 1, 2, 3, 4, 5, 6, "-doRayleigh", 1)
            rec["ele"] = self._etag
            self.joints.append(rec)
            return n

        self._jrng = np.random.default_rng(t.get("joint_seed", 1))
        # --- main tees (with splices when the connections are springs)
        for ci, i in enumerate(g.main_cols):
            splices = set()
            if springs:
                yoff = t["splice"]["offsets_m"][ci]
                y = yoff
                while y < g.ny * 0.6 - 1e-6:
                    splices.add(int(round(y / 0.6)))
                    y += 3.6
            prev = self.grid[(i, 0)]
            for j in range(1, g.ny + 1):
                cur = self.grid[(i, j)]
                beam(prev, cur, "main")
                prev = cur
                if j in splices and j < g.ny:
                    sp = t["splice"]
                    x, y, _ = ops.nodeCoord(cur)
                    n = self._new_node(x, y)
                    self._home[n] = cur
                    mats = [self._elastic(sp["transverse"]), self._elastic(sp["axial"]), self._elastic(sp["vertical"]),
                            self._elastic(sp["rot"]), self._elastic(sp["rot"]), self._elastic(sp["rot"])]
                    self._etag += 1
                    ops.element("zeroLength", self._etag, cur, n, "-mat", *mats, "-dir", 1, 2, 3, 4, 5, 6,
                                "-doRayleigh", 1)
                    prev = n
        # --- cross tees
        for j in range(g.ny + 1):
            for a, b in g.cross_pieces:
                nodes = []
                for i in range(a, b + 1):
                    if springs and i == a:
                        nodes.append(joint("main-cross", i, j, +1, t["joint_main_cross"]))
                    elif springs and i == b and b in g.main_cols:
                        nodes.append(joint("main-cross", i, j, -1, t["joint_main_cross"]))
                    else:
                        nodes.append(self.grid[(i, j)])
                for n1, n2 in zip(nodes[:-1], nodes[1:]):
                    beam(n1, n2, "cross")
        # --- sub cross tees
        for i in g.sub_cols:
            for j in range(g.ny):
                if springs:
                    n1 = joint("sub-cross", i, j, +1, t["joint_sub"])
                    n2 = joint("sub-cross", i, j + 1, -1, t["joint_sub"])
                else:
                    n1, n2 = self.grid[(i, j)], self.grid[(i, j + 1)]
                beam(n1, n2, "sub")
        # --- hanger rods
        self.rods = []
        rrng = np.random.default_rng(t.get("rod_seed", 2))
        first = int(round(t["rod_first_row_m"] / 0.6))
        for i in g.main_cols:
            for j in range(first, g.ny, 2):
                if j == 0 or j == g.ny:
                    continue
                gn = self.grid[(i, j)]
                x, y, _ = ops.nodeCoord(gn)
                L = t["rod_length_mm"] * (1 + t["rod_length_scatter"] * rrng.uniform(-1, 1))
                bot = self._new_node(x, y)
                self._rod_home[bot] = gn
                chain = [bot]
                for k in range(1, t["rod_elements"] + 1):
                    n = self._new_node(x, y, L * k / t["rod_elements"])
                    self._rod_home[n] = gn if k < t["rod_elements"] else None
                    chain.append(n)
                ops.fix(chain[-1], 1, 1, 1, 1, 1, 1)
                self._rod_home[chain[-1]] = None
                for n1, n2 in zip(chain[:-1], chain[1:]):
                    beam(n1, n2, "rod")
                stiff = 1e5
                mats = [self._elastic(stiff)] * 3
                dirs = [1, 2, 3]
                if t["rod_top"] == "rod_spring":
                    kr = t["rod_rot_spring"]
                    mats += [self._elastic(kr), self._elastic(kr)]
                    dirs += [4, 5]
                self._etag += 1
                ops.element("zeroLength", self._etag, gn, bot, "-mat", *mats, "-dir", *dirs, "-doRayleigh", 1)
                self.rods.append((i, j, L))
        # --- panels
        mp = t["panel_mass_kg"] * 1e-3
        k = 0
        for i in range(g.nx):
            for j in range(g.ny):
                m = mp * t["panel_factors"][k] / 4
                k += 1
                for di in (0, 1):
                    for dj in (0, 1):
                        self._add_mass(self.grid[(i + di, j + dj)], m)
        # --- perimeter
        P = t["perimeter"]
        self.ends = []
        for e, (i, j, axis, sign) in enumerate(g.ends):
            gn = self.grid[(i, j)]
            x, y, _ = ops.nodeCoord(gn)
            wall = self._new_node(x, y)
            ops.fix(wall, 1, 1, 1, 1, 1, 1)
            ka = P["K_along"] * P["along_factors"][e]
            rec = {"i": i, "j": j, "axis": axis, "sign": sign, "node": gn, "k_along": ka}
            if "perimeter-friction" in self.effects:
                sh = self.effects["perimeter-friction"]["shape"]
                fy = self.effects["perimeter-friction"]["per_end"][e]
                self._mat += 1
                if sh["law"] == "steel01":
                    ops.uniaxialMaterial("Steel01", self._mat, fy, ka, sh["hardening"])
                else:
                    # cR1 = 0: the knee keeps its roundness R0 on every cycle (no Bauschinger
                    # softening, which would smear the slip far below the slip force)
                    ops.uniaxialMaterial("Steel02", self._mat, fy, ka, sh["hardening"], sh["R0"], 0.0, 0.15)
                along = self._mat
                rec["slip_force"] = fy
                # Steel02 reaches Fy only past yield (rounded knee): detect slip at 0.95 Fy
                rec["slip_detect"] = 0.999 if sh["law"] == "steel01" else 0.95
            else:
                along = self._elastic(ka)
            # node order: the wall first on a low wall, the grid node first on a high
            # wall, so that moving towards the wall is always a negative deformation
            pair = (wall, gn) if sign < 0 else (gn, wall)
            self._etag += 1
            ops.element("zeroLength", self._etag, *pair, "-mat", along, "-dir", axis + 1, "-doRayleigh", 1)
            rec["ele_along"] = self._etag
            if "perimeter-pounding" in self.effects:
                # in parallel with the along spring (slipping or not): the contact
                # closes on the end's own displacement towards the wall
                sh = self.effects["perimeter-pounding"]["shape"]
                gap = self.effects["perimeter-pounding"]["per_end"][e]
                self._mat += 1
                if sh["law"] == "impact-bilinear":
                    ops.uniaxialMaterial("ImpactMaterial", self._mat, sh["k_contact"], sh["k_contact"] * sh["k2_ratio"],
                                         -sh["yield_disp"], -gap)
                else:
                    ops.uniaxialMaterial("ElasticPPGap", self._mat, sh["k_contact"], -1e9, -gap, 0.0, "noDamage")
                self._etag += 1
                ops.element("zeroLength", self._etag, *pair, "-mat", self._mat, "-dir", axis + 1)  # no Rayleigh
                rec["ele_contact"] = self._etag
                rec["gap"] = gap
            if not g.corner(i, j):
                kc = P["K_across"] * P["across_factors"][e]
                self._etag += 1
                ops.element("zeroLength", self._etag, wall, gn, "-mat", self._elastic(kc), "-dir", 2 - axis,
                            "-doRayleigh", 1)
            if not any(q["node"] == gn for q in self.ends):  # one vertical support per node
                self._etag += 1
                ops.element("zeroLength", self._etag, wall, gn, "-mat", self._elastic(P["K_vertical"]), "-dir", 3,
                            "-doRayleigh", 1)
            self.ends.append(rec)
        # --- masses
        if mform != "grid-node-lumped":
            # element mass is in the elements; only panels are nodal. Rebuild the nodal part.
            nodal = {n: 0.0 for n in self.node_mass}
            k = 0
            for i in range(g.nx):
                for j in range(g.ny):
                    m = mp * t["panel_factors"][k] / 4
                    k += 1
                    for di in (0, 1):
                        for dj in (0, 1):
                            nodal[self.grid[(i + di, j + dj)]] += m
        else:
            nodal = self.node_mass
        for n, m in nodal.items():
            if m > 0:
                ops.mass(n, m, m, m, 0.0, 0.0, 0.0)
        self.total_mass_t = sum(self.node_mass.values())

    def _hysteretic(self, k0, f1):
        sh = self.effects["connection-hysteresis"]["shape"]
        d1 = f1 / k0
        f2 = f1 * sh["r2"]
        d2 = d1 + (f2 - f1) / (k0 * sh["a2"])
        f3 = f2 * sh["r3"]
        d3 = d2 + (f3 - f2) / (k0 * sh["a3"])
        f4 = f3 * 1.02
        d4 = d3 * 10
        n = sh["neg_ratio"]
        self._mat += 1
        if sh["law"] == "pinching4":
            ops.uniaxialMaterial(
                "Pinching4", self._mat,
                f1, d1, f2, d2, f3, d3, f4, d4,
                -f1 * n, -d1 * n, -f2 * n, -d2 * n, -f3 * n, -d3 * n, -f4 * n, -d4 * n,
                sh["rDisp"], sh["rForce"], sh["uForce"], sh["rDisp"], sh["rForce"], sh["uForce"],
                sh["gK1"], 0.0, 1.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0, "cycle")
        else:
            ops.uniaxialMaterial(
                "Hysteretic", self._mat, f1, d1, f2, d2, f3, d3, -f1 * n, -d1 * n, -f2 * n, -d2 * n, -f3 * n, -d3 * n,
                sh["pinchX"], sh["pinchY"], 0.0, 0.0, sh["beta"])
        return self._mat

    # ------------------------------------------------------------------
    def eigen(self, n=12):
        """Frequencies (Hz) and each mode's horizontal share of kinetic energy."""
        lam = ops.eigen(n)
        out = []
        for k, l in enumerate(lam, start=1):
            h = v = 0.0
            for node, m in self.node_mass.items():
                if m <= 0:
                    continue
                ph = ops.nodeEigenvector(node, k)
                h += m * (ph[0] ** 2 + ph[1] ** 2)
                v += m * ph[2] ** 2
            # effective mass ratios in x and y
            out.append({"mode": k, "f_hz": math.sqrt(max(l, 0.0)) / (2 * math.pi),
                        "horizontal_share": h / (h + v) if h + v > 0 else 0.0})
        return out

    def set_damping(self, alpha_m, beta_k, tangent):
        if tangent == "initial":
            ops.rayleigh(alpha_m, 0.0, beta_k, 0.0)
        else:
            ops.rayleigh(alpha_m, 0.0, 0.0, beta_k)

    # ------------------------------------------------------------------
    def simulate(self, ax, ay, dt, nsub, sensor_nodes, track=None, linear=False):
        """Base accelerations ax, ay (mm/s2, arrays or None) sampled at dt; nsub
        integration steps per sample. Returns relative displacement and relative
        acceleration (mm, mm/s2) of `sensor_nodes` at every integration step
        (arrays [nsteps+1, len(nodes), 2]), plus the tracking summary."""
        npts = len(ax) if ax is not None else len(ay)
        ts = 100
        for d, a in ((1, ax), (2, ay)):
            if a is None:
                continue
            ts += 1
            ops.timeSeries("Path", ts, "-dt", dt, "-values", *[float(v) for v in a])
            ops.pattern("UniformExcitation", ts, d, "-accel", ts)
        ops.constraints("Plain")
        ops.numberer("RCM")
        ops.system("SparseSYM")
        # unbalance test: a step that stays linear converges after one factorization
        ops.test("NormUnbalance", 1e-5, 40)
        self._algo = ["Linear", "-factorOnce"] if linear else ["Newton"]
        ops.algorithm(*self._algo)
        ops.integrator("Newmark", 0.5, 0.25)
        ops.analysis("Transient")
        h = dt / nsub
        nsteps = (npts - 1) * nsub
        ns = len(sensor_nodes)
        disp = np.zeros((nsteps + 1, ns, 2))
        acc = np.zeros((nsteps + 1, ns, 2))
        tr = Tracker(self, track) if track else None
        self.halvings = 0
        self.retried = 0
        self.newton_steps = 0
        for s in range(1, nsteps + 1):
            ok = ops.analyze(1, h)
            if ok != 0:
                ok = self._retry(h, linear)
                if ok != 0:
                    raise SimulationError(f"OpenSees step {s} (t = {s * h:.4f} s) failed after halving the step "
                                          f"4 times and trying other algorithms")
            for k, n in enumerate(sensor_nodes):
                dd = ops.nodeDisp(n)
                aa = ops.nodeAccel(n)
                disp[s, k, 0], disp[s, k, 1] = dd[0], dd[1]
                acc[s, k, 0], acc[s, k, 1] = aa[0], aa[1]
            if tr and s % nsub == 0:
                tr.sample()
        return disp, acc, (tr.summary() if tr else None)

    def _retry(self, h, linear, depth=4):
        """The step h failed (OpenSees reverted it): try other algorithms, then
        two half steps, recursively, at most `depth` halvings."""
        for algo in (["Newton"], ["KrylovNewton"]):
            ops.algorithm(*algo)
            ok = ops.analyze(1, h)
            ops.algorithm(*self._algo)
            if ok == 0:
                if algo[0] == "Newton":
                    self.newton_steps += 1
                else:
                    self.retried += 1
                return 0
        if depth == 0:
            return -1
        for _ in range(2):
            if ops.analyze(1, h / 2) != 0 and self._retry(h / 2, linear, depth - 1) != 0:
                return -1
        self.halvings += 1
        return 0


class Tracker:
    """Peaks and events of the perimeter ends and connections, one read a sample."""

    def __init__(self, model, what):
        self.m = model
        self.what = what
        ne = len(model.ends)
        self.peak_toward = np.zeros(ne)  # max displacement towards the wall (mm)
        self.peak_abs = np.zeros(ne)
        self.last = np.zeros(ne)
        self.contact_events = 0
        self.contact_samples = 0
        self.slip_events = 0
        self.slip_samples = 0
        self.was_contact = np.zeros(ne, dtype=bool)
        self.was_slip = np.zeros(ne, dtype=bool)  # an end may both pound and slip
        mj = [q for q in model.joints if q["kind"] == "main-cross"]
        self.mj = mj
        self.jpeak = np.zeros((len(mj), 2))
        self.jwas = np.zeros((len(mj), 2), dtype=bool)
        self.yield_events = 0
        self.yield_samples = 0

    def sample(self):
        m = self.m
        if self.what in ("perimeter", "all"):
            for e, rec in enumerate(m.ends):
                d = ops.nodeDisp(rec["node"], rec["axis"] + 1)
                w = rec["sign"] * d
                if w > self.peak_toward[e]:
                    self.peak_toward[e] = w
                if abs(d) > self.peak_abs[e]:
                    self.peak_abs[e] = abs(d)
                self.last[e] = d
                if "ele_contact" in rec:
                    now = w > rec["gap"]
                    self.contact_samples += now
                    if now and not self.was_contact[e]:
                        self.contact_events += 1
                    self.was_contact[e] = now
                if "slip_force" in rec:
                    f = ops.eleResponse(rec["ele_along"], "basicForce")[0]
                    now = abs(f) >= rec["slip_detect"] * rec["slip_force"]
                    self.slip_samples += now
                    if now and not self.was_slip[e]:
                        self.slip_events += 1
                    self.was_slip[e] = now
        if self.what in ("joints", "all"):
            for q, rec in enumerate(self.mj):
                f = ops.eleResponse(rec["ele"], "basicForce")
                for d in (0, 1):
                    a = abs(f[d])
                    if a > self.jpeak[q, d]:
                        self.jpeak[q, d] = a
                    y = rec.get("yield")
                    if y:
                        now = a >= 0.999 * y[d]
                        self.yield_samples += now
                        if now and not self.jwas[q, d]:
                            self.yield_events += 1
                        self.jwas[q, d] = now

    def summary(self):
        return {"peak_toward": self.peak_toward.tolist(), "peak_abs": self.peak_abs.tolist(),
                "residual": self.last.tolist(), "joint_peak": self.jpeak.tolist(),
                "contact_events": int(self.contact_events), "contact_samples": int(self.contact_samples),
                "slip_events": int(self.slip_events), "slip_samples": int(self.slip_samples),
                "yield_events": int(self.yield_events), "yield_samples": int(self.yield_samples)}
