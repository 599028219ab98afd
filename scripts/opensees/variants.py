"""Named changes of model form applied to an exported run model before OpenSees builds it.

An exported `ceiling-fe-model` is the very model ceilfarm simulates, so OpenSees
on it only checks the solver. A variant changes the model's form the way a
different simulator, or a real specimen, would: another contact law, scatter
from spring to spring, another hysteresis shape, another damping. Each variant
is a pure function of the model and a seed; a factor drawn for a spring depends
only on (seed, variant, spring id), so every run of a campaign (they share the
mesh) sees the same specimen.

    import variants
    m2, report = variants.apply(model_dict, ["contact-impact", "gap-scatter"], seed=1)

Variants (units of the model file: N, mm, s, t):

* contact-impact: springs of material type Gap become ImpactMaterial:
  K1 = the gap's k, K2 = 0.3 K1, dy = 0.1 mm, same gap. Beware: in
  OpenSeesPy 3.8 ImpactMaterial keeps state from uncommitted trials (a trial
  strain followed by a commit elsewhere shifts its contact point), so Newton
  iterations drift and a pounding campaign stops converging (sx: step 443
  fails even at dt/64); contact-stiffening is the usable other contact law.
* contact-stiffening: a stiffening two-stage contact instead of the linear
  one: each Gap spring keeps its gap with 0.25 k, and a parallel Gap spring
  (same nodes and dof) adds 1.5 k from 0.1 mm further in (a wall angle that
  bends before it bears). Both stages elastic.
* contact-softening: each Gap spring becomes an elastic bilinear contact with
  ImpactMaterial's envelope (the seed's simplified model: K1 = k for the first
  0.1 mm, then K2 = 0.3 K1), re-centring and without memory (OpenSees
  ElasticMultiLinear), so that it converges where ImpactMaterial does not.
* gap-scatter: each gap spring's opening (Gap or Impact `gap`, both stages of
  a stiffening contact) times a factor uniform in [0.7, 1.3].
* gap-scatter-measured: the same with the seed's measured spread (sd 1.86 mm
  on 17.33 mm at a fixed-semi-free perimeter, 4.2.1): uniform in
  [1 - 0.107 sqrt(3), 1 + 0.107 sqrt(3)] = [0.814, 1.186].
* friction-scatter: each `perimeter_friction` spring of material Steel01 gets
  Fy times a factor uniform in [0.7, 1.3] and post-slip ratio b times 3.
* friction-smooth: each Steel01 perimeter-friction spring becomes Steel02
  (Giuffre-Menegotto-Pinto) with the same Fy, E0 and b and a rounded
  transition (R0 = 3, cR1 = 0.925, cR2 = 0.15): slip that starts gradually,
  as a Wen plastic link with a low exponent does.
* pinching-flag: each Pinching4 spring becomes OpenSees SelfCentering
  (flag-shaped loops, symmetric): initial stiffness and activation force from
  the first point of its positive envelope, the stiffness after activation
  from its first segment, beta 0.6: another pinched law than Pinching4's.
  (OpenSees Hysteretic, the obvious other choice, reports tangents that do
  not follow its own unloading path and stalls Newton even on the initial
  tangent.)
* pinching-shape: each Pinching4 spring gets rDisp 0.5, rForce 0.5, uForce 0.1
  on both sides (the exported shape is replaced) and its envelope forces times
  a factor uniform in [0.8, 1.2] (initial stiffness scales with it).
* mass-scatter: each node's translational mass times a factor uniform in
  [0.85, 1.15] (panels of different weight, sensors and cables, another
  lumping of the members' mass): a linear misfit no extension models.
* member-scatter: each beam's E times a factor uniform in [0.85, 1.15]
  (member-to-member scatter of section and stiffness): another one.
* carrying-channels: on a double-layer model (meta layers = 2, which the
  ceilfarm generator builds without them) the seed's carrying channels
  U50x15x1 (2.24 kg/m, 70 mm2) along X through every row of rods: their
  mass over the plan's length, shared among the row's rod nodes, and an
  elastic beam between neighbouring rod nodes, rigidly joined (the clips'
  give left out: the most a channel can tie the main tees).
* channel-mass: the channels' mass alone, as carrying-channels adds it,
  without their beams (what of carrying-channels the mass explains).
* fine-steps: the time step divided by 10 (output at the same instants):
  a simulator that resolves contact and slip in time, where ceilfarm
  integrates at the sampling step (a grid end on a 0.4 EA/L contact rings
  at a period below 10 ms).
* damping-shift: Rayleigh re-targeted to 1.5 zeta at the lower anchor (the
  lowest target frequency) and 0.7 zeta at 4 times it.
* damping-tangent: Rayleigh's stiffness term on the last committed tangent
  (OpenSees betaKcomm) instead of the initial stiffness (betaKinit), same
  coefficients: a slipping or yielding spring stops damping, as in the
  OpenSees scripts that damp on the tangent. (On the current tangent,
  betaK, the damping force jumps within a step where a spring yields, and
  Newton stalls on Pinching4 connections even at dt/64 and 1e-6 mm.)
  run_campaign.py applies it.

A variant whose target is absent (no gap, no Steel01 friction spring, no
Pinching4) leaves the model as it is and says so in its report.
"""
import copy
import math
import random

IMPACT_K2_RATIO = 0.3
IMPACT_DY_MM = 0.1
GAP_SCATTER = (0.7, 1.3)
GAP_SCATTER_MEASURED = (1.0 - 1.86 / 17.33 * math.sqrt(3.0), 1.0 + 1.86 / 17.33 * math.sqrt(3.0))
FRICTION_FY_SCATTER = (0.7, 1.3)
FRICTION_B_FACTOR = 3.0
STIFFENING_FIRST = 0.25
STIFFENING_SECOND = 1.5
STIFFENING_OFFSET_MM = 0.1
PINCHING_SHAPE = {"rDispP": 0.5, "rForceP": 0.5, "uForceP": 0.1,
                  "rDispN": 0.5, "rForceN": 0.5, "uForceN": 0.1}
PINCHING_STRENGTH = (0.8, 1.2)
SOFTENING_K2_RATIO = 0.3
SOFTENING_DY_MM = 0.1
SMOOTH_STEEL02 = (3.0, 0.925, 0.15)
FLAG_BETA = 0.6
MASS_SCATTER = (0.85, 1.15)
MEMBER_SCATTER = (0.85, 1.15)
CHANNEL_KG_PER_M = 2.24
CHANNEL = {"A": 70.0, "Iy": 2.9e4, "Iz": 1.6e3, "J": 27.0}   # mm2, mm4: U50x15x1, web vertical
FINE_STEPS = 10
DAMPING_LOW_FACTOR = 1.5
DAMPING_HIGH_FACTOR = 0.7
DAMPING_HIGH_OVER_LOW = 4.0


def factor(seed, variant, spring_id, lo, hi):
    """A factor uniform in [lo, hi], fixed by (seed, variant, spring id)."""
    return random.Random("%s|%s|%s" % (seed, variant, spring_id)).uniform(lo, hi)


def materials(m):
    return {mat["id"]: mat for mat in m.get("materials", [])}


def springs_of(m, pred):
    """Springs whose (spring, material) satisfy pred."""
    mats = materials(m)
    return [s for s in m.get("springs", []) if pred(s, mats[s["mat"]])]


def own_material(m, spring, new_mat):
    """Gives spring its own material new_mat (a fresh id)."""
    new_id = max(mat["id"] for mat in m["materials"]) + 1
    new_mat = dict(new_mat, id=new_id)
    m["materials"].append(new_mat)
    spring["mat"] = new_id
    return new_mat


def next_element_id(m):
    """An id after every spring's and beam's (elements share one id space)."""
    return max([s["id"] for s in m.get("springs", [])] + [b["id"] for b in m.get("beams", [])]) + 1


def summary(values):
    if not values:
        return None
    return {"min": min(values), "max": max(values),
            "mean": sum(values) / len(values), "n": len(values)}


def absent(what):
    return {"applied": False, "note": "no %s in this model: left unchanged" % what}


def contact_impact(m, seed):
    """Gap springs -> ImpactMaterial (K1 = k, K2 = 0.3 K1, dy = 0.1 mm, same gap)."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Gap")
    if not targets:
        return absent("Gap spring")
    done = {}
    for s in targets:
        old = materials(m)[s["mat"]]
        if old["id"] not in done:
            k = old["k"]
            done[old["id"]] = {"type": "Impact", "K1": k, "K2": IMPACT_K2_RATIO * k,
                               "dy": IMPACT_DY_MM, "gap": old["gap"]}
    for mid, new in done.items():
        mat = materials(m)[mid]
        for key in list(mat):
            if key != "id":
                del mat[key]
        mat.update(new)
    return {"applied": True, "n_springs": len(targets), "n_materials": len(done),
            "K2_over_K1": IMPACT_K2_RATIO, "dy_mm": IMPACT_DY_MM,
            "K1_N_per_mm": sorted({v["K1"] for v in done.values()})}


def contact_stiffening(m, seed):
    """Gap spring -> 0.25 k from its gap, plus a parallel 1.5 k from 0.1 mm further."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Gap")
    if not targets:
        return absent("Gap spring")
    next_id = next_element_id(m)
    added = []
    for s in targets:
        old = materials(m)[s["mat"]]
        first = own_material(m, s, dict(old, k=STIFFENING_FIRST * old["k"]))
        second = dict(s, id=next_id, parent=s["id"])
        own_material(m, second, dict(old, k=STIFFENING_SECOND * old["k"],
                                     gap=old["gap"] + STIFFENING_OFFSET_MM))
        second["group"] = s.get("group", "perimeter_gap") + "_stage2"
        added.append(second)
        next_id += 1
        assert first["gap"] == old["gap"]
    m["springs"].extend(added)
    return {"applied": True, "n_springs": len(targets), "k_first_over_k": STIFFENING_FIRST,
            "k_second_over_k": STIFFENING_SECOND, "second_offset_mm": STIFFENING_OFFSET_MM,
            "contact_k_at_gap_plus_0.1mm_over_k": STIFFENING_FIRST + STIFFENING_SECOND}


def gap_scatter(m, seed, name="gap-scatter", spread=GAP_SCATTER):
    """Each gap spring's opening times U[spread] (a stage-2 spring: its parent's factor)."""
    targets = springs_of(m, lambda s, mat: mat["type"] in ("Gap", "Impact"))
    if not targets:
        return absent("Gap or Impact spring")
    fs, gaps = [], []
    for s in targets:
        f = factor(seed, name, s.get("parent", s["id"]), *spread)
        mat = own_material(m, s, materials(m)[s["mat"]])
        mat["gap"] = mat["gap"] * f
        fs.append(f)
        gaps.append(mat["gap"])
    return {"applied": True, "n_springs": len(targets), "factor": summary(fs),
            "gap_mm": summary(gaps)}


def gap_scatter_measured(m, seed):
    """Each gap spring's opening times U[0.814, 1.186], the seed's measured spread."""
    return gap_scatter(m, seed, "gap-scatter-measured", GAP_SCATTER_MEASURED)


def friction_scatter(m, seed):
    """Each Steel01 perimeter-friction spring: Fy times U[0.7, 1.3], b times 3."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Steel01"
                         and s.get("group", "perimeter_friction") == "perimeter_friction")
    if not targets:
        return absent("Steel01 perimeter-friction spring")
    fs, fys, bs = [], [], []
    for s in targets:
        f = factor(seed, "friction-scatter", s["id"], *FRICTION_FY_SCATTER)
        mat = own_material(m, s, materials(m)[s["mat"]])
        mat["Fy"] = mat["Fy"] * f
        mat["b"] = mat["b"] * FRICTION_B_FACTOR
        fs.append(f)
        fys.append(mat["Fy"])
        bs.append(mat["b"])
    return {"applied": True, "n_springs": len(targets), "Fy_factor": summary(fs),
            "Fy_N": summary(fys), "b": sorted(set(bs))}


def pinching_shape(m, seed):
    """Each Pinching4 spring: another pinching shape and envelope forces times U[0.8, 1.2]."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Pinching4")
    if not targets:
        return absent("Pinching4 spring")
    before = {k: materials(m)[targets[0]["mat"]][k] for k in PINCHING_SHAPE}
    fs = []
    for s in targets:
        f = factor(seed, "pinching-shape", s["id"], *PINCHING_STRENGTH)
        mat = own_material(m, s, copy.deepcopy(materials(m)[s["mat"]]))
        mat.update(PINCHING_SHAPE)
        mat["ePf"] = [v * f for v in mat["ePf"]]
        mat["eNf"] = [v * f for v in mat["eNf"]]
        fs.append(f)
    return {"applied": True, "n_springs": len(targets), "shape_before": before,
            "shape_after": dict(PINCHING_SHAPE), "strength_factor": summary(fs)}


def contact_softening(m, seed):
    """Gap springs -> elastic bilinear contact: k for 0.1 mm past the gap, then 0.3 k."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Gap")
    if not targets:
        return absent("Gap spring")
    for s in targets:
        old = materials(m)[s["mat"]]
        k, gap = old["k"], abs(old["gap"])
        far = 1e3
        f1 = k * SOFTENING_DY_MM
        strain = [-far, -gap - SOFTENING_DY_MM, -gap, far]
        stress = [-f1 - SOFTENING_K2_RATIO * k * (far - gap - SOFTENING_DY_MM), -f1, 0.0, 0.0]
        cmd = ["ElasticMultiLinear", 0.0, "-strain", *strain, "-stress", *stress]
        own_material(m, s, {"type": "OpenSees", "cmd": cmd, "gap": gap, "k": k,
                            "note": "contact-softening variant"})
    return {"applied": True, "n_springs": len(targets), "K2_over_K1": SOFTENING_K2_RATIO,
            "dy_mm": SOFTENING_DY_MM}


def friction_smooth(m, seed):
    """Each Steel01 perimeter-friction spring -> Steel02 with a rounded transition."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Steel01"
                         and s.get("group", "perimeter_friction") == "perimeter_friction")
    if not targets:
        return absent("Steel01 perimeter-friction spring")
    for s in targets:
        old = materials(m)[s["mat"]]
        cmd = ["Steel02", old["Fy"], old["E0"], old["b"], *SMOOTH_STEEL02]
        own_material(m, s, {"type": "OpenSees", "cmd": cmd, "note": "friction-smooth variant"})
    return {"applied": True, "n_springs": len(targets), "R0_cR1_cR2": list(SMOOTH_STEEL02)}


def pinching_flag(m, seed):
    """Each Pinching4 spring -> OpenSees SelfCentering on its first envelope segment."""
    targets = springs_of(m, lambda s, mat: mat["type"] == "Pinching4")
    if not targets:
        return absent("Pinching4 spring")
    for s in targets:
        old = materials(m)[s["mat"]]
        (f1, f2), (d1, d2) = old["ePf"][:2], old["ePd"][:2]
        cmd = ["SelfCentering", f1 / d1, (f2 - f1) / (d2 - d1), f1, FLAG_BETA]
        own_material(m, s, {"type": "OpenSees", "cmd": cmd, "note": "pinching-flag variant"})
    return {"applied": True, "n_springs": len(targets), "beta": FLAG_BETA}


def mass_scatter(m, seed):
    """Each node's translational mass times U[0.85, 1.15]."""
    masses = m.get("masses", [])
    if not masses:
        return absent("nodal mass")
    fs = []
    for entry in masses:
        f = factor(seed, "mass-scatter", entry["node"], *MASS_SCATTER)
        entry["m"] = [v * f if k < 3 else v for k, v in enumerate(entry["m"])]
        fs.append(f)
    return {"applied": True, "n_nodes": len(fs), "factor": summary(fs)}


def channel_mass(m, seed):
    """The carrying channels' mass alone (no beams)."""
    return carrying_channels(m, seed, beams=False)


def carrying_channels(m, seed, beams=True):
    """Channels along X through each row of rod nodes: mass and beams."""
    if m.get("meta", {}).get("layers") != 2:
        return absent("double layer")
    xyz = {n[0]: n[1:] for n in m["nodes"]}
    rods = [b for b in m.get("beams", []) if b.get("group") == "rod"]
    bottom = [min((b["i"], b["j"]), key=lambda n: xyz[n][2]) for b in rods]
    rows = {}
    for n in set(bottom):
        rows.setdefault(round(xyz[n][1], 3), []).append(n)
    ref = next(b for b in m["beams"] if b.get("group") == "main_tee")
    first_id = next_id = next_element_id(m)
    masses = {e["node"]: e for e in m.setdefault("masses", [])}
    length_mm = m["meta"]["Lx"]
    added_t = 0.0
    for _, row in sorted(rows.items()):
        row.sort(key=lambda n: xyz[n][0])
        share_t = CHANNEL_KG_PER_M * 1e-6 * length_mm / len(row)
        for n in row:
            if n not in masses:
                masses[n] = {"node": n, "m": [0.0] * 6}
                m["masses"].append(masses[n])
            masses[n]["m"] = [v + share_t if k < 3 else v for k, v in enumerate(masses[n]["m"])]
            added_t += share_t
        if beams:
            for a, b in zip(row, row[1:]):
                m["beams"].append(dict(CHANNEL, id=next_id, i=a, j=b, E=ref["E"], G=ref["G"],
                                       vecxz=[0.0, 0.0, 1.0], group="carrying_channel"))
                next_id += 1
    before = m["meta"].get("mass_total_t")
    return {"applied": True, "rows": len(rows), "rod_nodes": len(bottom),
            "n_beams": next_id - first_id, "mass_added_t": added_t,
            "mass_added_over_total": added_t / before if before else None}


def member_scatter(m, seed):
    """Each beam's E times U[0.85, 1.15]."""
    beams = m.get("beams", [])
    if not beams:
        return absent("beam")
    fs = []
    for b in beams:
        f = factor(seed, "member-scatter", b["id"], *MEMBER_SCATTER)
        b["E"] *= f
        fs.append(f)
    return {"applied": True, "n_beams": len(fs), "factor": summary(fs)}


def fine_steps(m, seed):
    """The analysis step divided by FINE_STEPS, output at the same instants."""
    an = m.get("analysis")
    if not an or "dt" not in an or "n_steps" not in an:
        return absent("transient analysis")
    before = an["dt"]
    an["dt"] = before / FINE_STEPS
    an["n_steps"] = an["n_steps"] * FINE_STEPS
    an["output_every_n_steps"] = an.get("output_every_n_steps", 1) * FINE_STEPS
    return {"applied": True, "dt_s": [before, an["dt"]]}


def rayleigh_zeta(alpha, beta, f_hz):
    w = 2 * math.pi * f_hz
    return alpha / (2 * w) + beta * w / 2


def damping_shift(m, seed):
    """Rayleigh through 1.5 zeta at the lowest target frequency and 0.7 zeta at 4 times it."""
    d = m.get("damping")
    if not d or d.get("type") != "rayleigh" or "target" not in d:
        return absent("Rayleigh damping with a target")
    zeta = d["target"]["zeta"]
    f1 = min(d["target"]["f_hz"])
    f2 = DAMPING_HIGH_OVER_LOW * f1
    z1, z2 = DAMPING_LOW_FACTOR * zeta, DAMPING_HIGH_FACTOR * zeta
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2
    # z_i = alpha / (2 w_i) + beta w_i / 2, solved for (alpha, beta)
    beta = 2 * (z2 * w2 - z1 * w1) / (w2 * w2 - w1 * w1)
    alpha = 2 * w1 * z1 - beta * w1 * w1
    old = (d["alphaM"], d["betaK"])
    d["alphaM"], d["betaK"] = alpha, beta
    d["target"] = {"f_hz": [f1, f2], "zeta": [z1, z2], "modes": "damping-shift variant",
                   "exported": d["target"]}
    probe = [f1, 2 * f1, f2]
    return {"applied": True, "alphaM": [old[0], alpha], "betaK": [old[1], beta],
            "zeta_at_f_hz": {"%.3f" % f: [rayleigh_zeta(*old, f), rayleigh_zeta(alpha, beta, f)]
                             for f in probe}}


def damping_tangent(m, seed):
    """Rayleigh's stiffness term on the last committed tangent instead of the initial stiffness."""
    d = m.get("damping")
    if not d or d.get("type") != "rayleigh" or d.get("stiffness") != "initial":
        return absent("Rayleigh damping on the initial stiffness")
    d["stiffness"] = "committed"
    nonlinear = {mat["id"] for mat in m.get("materials", [])
                 if mat["type"] not in ("Elastic", "Gap")}
    n = sum(1 for s in m.get("springs", []) if s.get("rayleigh") and s["mat"] in nonlinear)
    return {"applied": True, "stiffness": ["initial", "committed"],
            "damped_nonlinear_springs": n}


VARIANTS = {
    "contact-impact": contact_impact,
    "contact-stiffening": contact_stiffening,
    "contact-softening": contact_softening,
    "gap-scatter": gap_scatter,
    "gap-scatter-measured": gap_scatter_measured,
    "friction-scatter": friction_scatter,
    "friction-smooth": friction_smooth,
    "pinching-shape": pinching_shape,
    "pinching-flag": pinching_flag,
    "mass-scatter": mass_scatter,
    "carrying-channels": carrying_channels,
    "channel-mass": channel_mass,
    "member-scatter": member_scatter,
    "fine-steps": fine_steps,
    "damping-shift": damping_shift,
    "damping-tangent": damping_tangent,
}
# contact law first, then scatter of whatever gap material results
ORDER = ["contact-impact", "contact-stiffening", "contact-softening", "gap-scatter",
         "gap-scatter-measured",
         "friction-scatter", "friction-smooth", "pinching-shape", "pinching-flag",
         "carrying-channels", "channel-mass", "mass-scatter", "member-scatter", "fine-steps", "damping-shift", "damping-tangent"]


def parse(text):
    """'a,b' -> ['a', 'b'] in canonical order; refuses unknown names."""
    names = [n.strip() for n in (text or "").split(",") if n.strip()]
    unknown = [n for n in names if n not in VARIANTS]
    if unknown:
        raise ValueError("unknown variant %s: expected some of %s" % (unknown, ORDER))
    return [n for n in ORDER if n in names]


def apply(model, names, seed=0):
    """A transformed copy of model (dict) and {variant: report}."""
    m = copy.deepcopy(model)
    m.pop("_dir", None)
    report = {}
    for name in parse(",".join(names)):
        report[name] = VARIANTS[name](m, seed)
    if report:
        m.setdefault("meta", {})["variants"] = {"names": list(report), "seed": seed}
    return m, report


def self_check():
    """Checks on a tiny model: the damping fit hits its anchors; factors are reproducible."""
    m = {"materials": [{"id": 1, "type": "Gap", "k": 100.0, "gap": 0.5},
                       {"id": 2, "type": "Steel01", "Fy": 5.0, "E0": 20.0, "b": 0.05}],
         "springs": [{"id": 10, "mat": 1}, {"id": 11, "mat": 1},
                     {"id": 12, "mat": 2, "group": "perimeter_friction"}],
         "damping": {"type": "rayleigh", "alphaM": 1.0, "betaK": 1e-3, "stiffness": "initial",
                     "target": {"f_hz": [10.0, 10.5], "zeta": 0.04}}}
    first = ["contact-impact", "gap-scatter", "friction-scatter", "pinching-shape", "damping-shift"]
    a, ra = apply(m, first, seed=7)
    b, _ = apply(m, first, seed=7)
    c, _ = apply(m, first, seed=8)
    assert a == b and a != c
    d = a["damping"]
    assert abs(rayleigh_zeta(d["alphaM"], d["betaK"], 10.0) - 0.06) < 1e-12
    assert abs(rayleigh_zeta(d["alphaM"], d["betaK"], 40.0) - 0.028) < 1e-12
    mats = {x["id"]: x for x in a["materials"]}
    gaps = [mats[s["mat"]] for s in a["springs"] if s["id"] in (10, 11)]
    assert all(g["type"] == "Impact" and g["K2"] == 30.0 for g in gaps)
    assert all(0.35 <= g["gap"] <= 0.65 for g in gaps) and gaps[0]["gap"] != gaps[1]["gap"]
    fr = mats[a["springs"][2]["mat"]]
    assert 3.5 <= fr["Fy"] <= 6.5 and abs(fr["b"] - 0.15) < 1e-15
    assert ra["pinching-shape"]["applied"] is False
    assert m["materials"][0]["type"] == "Gap"          # the input is untouched
    s, rs = apply(m, ["contact-stiffening", "gap-scatter"], seed=7)
    mats = {x["id"]: x for x in s["materials"]}
    by_parent = {sp["parent"]: mats[sp["mat"]] for sp in s["springs"] if "parent" in sp}
    for sp in s["springs"]:
        if sp["id"] in (10, 11):
            g1, g2 = mats[sp["mat"]], by_parent[sp["id"]]
            assert g1["k"] == 25.0 and g2["k"] == 150.0
            assert abs(g2["gap"] / g1["gap"] - 0.6 / 0.5) < 1e-12   # same factor on both stages
    assert len(s["springs"]) == 5 and rs["gap-scatter"]["n_springs"] == 4
    g, rg = apply(m, ["gap-scatter-measured"], seed=7)
    mats = {x["id"]: x for x in g["materials"]}
    f = [mats[sp["mat"]]["gap"] / 0.5 for sp in g["springs"] if sp["id"] in (10, 11)]
    assert all(0.814 < v < 1.186 for v in f) and f[0] != f[1], f
    assert rg["gap-scatter-measured"]["applied"]
    o, ro = apply(m, ["contact-softening", "friction-smooth", "pinching-flag"], seed=7)
    mats = {x["id"]: x for x in o["materials"]}
    soft = mats[o["springs"][0]["mat"]]
    assert soft["type"] == "OpenSees" and soft["cmd"][0] == "ElasticMultiLinear"
    strain, stress = soft["cmd"][3:7], soft["cmd"][8:12]
    assert strain[1:3] == [-0.6, -0.5] and stress[1:] == [-10.0, 0.0, 0.0]
    slope = (stress[1] - stress[0]) / (strain[1] - strain[0])
    assert abs(slope - 30.0) < 1e-9                 # K2 = 0.3 K1 beyond the first 0.1 mm
    assert mats[o["springs"][2]["mat"]]["cmd"][:4] == ["Steel02", 5.0, 20.0, 0.05]
    assert ro["pinching-flag"]["applied"] is False
    t, rt = apply(m, ["damping-tangent"], seed=7)
    assert t["damping"]["stiffness"] == "committed" and m["damping"]["stiffness"] == "initial"
    assert (t["damping"]["alphaM"], t["damping"]["betaK"]) == (1.0, 1e-3)
    t2, rt2 = apply(t, ["damping-tangent"], seed=7)
    assert rt2["damping-tangent"]["applied"] is False   # already on the tangent
    ch = {"nodes": [[1, 0.0, 0.0, 0.0], [2, 1200.0, 0.0, 0.0], [3, 0.0, 0.0, 900.0],
                    [4, 1200.0, 0.0, 900.0]],
          "beams": [{"id": 1, "i": 1, "j": 2, "E": 2e5, "G": 8e4, "group": "main_tee"},
                    {"id": 2, "i": 3, "j": 1, "group": "rod"}, {"id": 3, "i": 2, "j": 4, "group": "rod"}],
          "masses": [{"node": 1, "m": [1e-3] * 3 + [0.0] * 3}], "meta": {"layers": 2, "Lx": 2400.0}}
    c2, rc = apply(ch, ["carrying-channels"], seed=7)
    chan = [b for b in c2["beams"] if b["group"] == "carrying_channel"]
    assert len(chan) == 1 and (chan[0]["i"], chan[0]["j"]) == (1, 2) and chan[0]["id"] == 4
    added = {e["node"]: e["m"][0] for e in c2["masses"]}
    assert abs(added[1] - 1e-3 - 2.688e-3) < 1e-12 and abs(added[2] - 2.688e-3) < 1e-12
    _, r1 = apply(dict(ch, meta={"layers": 1, "Lx": 2400.0}), ["carrying-channels"], seed=7)
    assert r1["carrying-channels"]["applied"] is False
    c3, _ = apply(ch, ["channel-mass"], seed=7)
    assert len(c3["beams"]) == 3 and c3["masses"] == c2["masses"]
    return True


if __name__ == "__main__":
    print("variants self-check:", "ok" if self_check() else "FAILED")
