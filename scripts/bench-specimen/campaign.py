#!/usr/bin/env python3
"""One bench campaign of the second truth family, drawn from a seed.

    campaign.py SEED --out DIR [--effect none|EFFECT[+EFFECT...]]
                               [--strength weak|moderate|strong] [--plan LXxLY] [--dry-run]

    EFFECT: perimeter-pounding, perimeter-friction, connection-hysteresis

The hidden cause rotates with the seed (seed-1 mod 4: none, pounding, friction,
hysteresis; strength (seed-1) div 4 mod 3: strong, moderate, weak); --effect
and --strength override it. Everything else is drawn from the seed. --effect
may hide several effects at once, joined by '+' in any order (each once, never
with none): the answer's cause names them in the order above, each is sized
at --strength from the linear strong-run demand as it would be alone, and
each must act in the strong run (else the campaign fails, writing nothing).

Writes DIR as a `ceiling-measured/1` bundle (three 30 s sine sweeps at 200 Hz:
weak and moderate calibrate, strong validates) and DIR/../NAME.truth.json
(NAME = the bundle's name, DIR's base name) with the hidden cause, its
strength and every modelling choice. Exits non-zero, writing nothing, when
OpenSees fails a step even after halving it.
"""

import argparse
import json
import math
import os
import re
import shutil
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import truth as T  # noqa: E402

EFFECTS = ["none", "perimeter-pounding", "perimeter-friction", "connection-hysteresis"]
REGISTRY = EFFECTS[1:]  # the order a set of hidden effects is named in (ceilfarm's class names)
STRENGTHS = {"strong": 0.3, "moderate": 0.55, "weak": 0.8}  # fraction of the linear strong-run demand
FS = 200.0
DURATION = 30.0


def sweep(n, dt, f0, f1, taper, phase=0.0):
    """Unit-peak exponential sine sweep from f0 to f1 Hz, cosine-tapered ends."""
    t = np.arange(n) * dt
    T_ = t[-1]
    k = math.log(f1 / f0) / T_
    ph = 2 * math.pi * f0 * (np.exp(k * t) - 1) / k + phase
    a = np.sin(ph)
    w = np.ones(n)
    m = int(taper / dt)
    w[:m] = 0.5 - 0.5 * np.cos(np.pi * np.arange(m) / m)
    w[n - m:] = w[:m][::-1]
    return a * w


def effect_set(text):
    """--effect: 'none' or a '+'-joined set of effect names, any order, each once.
    Returns the cause's name: the set in REGISTRY order joined by '+'."""
    parts = text.split("+")
    if any(q.strip() == "" for q in parts):
        raise argparse.ArgumentTypeError(f"'{text}': an empty effect name (a '+' at an end or twice)")
    for q in parts:
        if q not in EFFECTS:
            raise argparse.ArgumentTypeError(f"'{text}': unknown effect '{q}' (choose from {', '.join(EFFECTS)})")
    if len(set(parts)) != len(parts):
        dup = sorted({q for q in parts if parts.count(q) > 1})
        raise argparse.ArgumentTypeError(f"'{text}': {', '.join(dup)} named more than once")
    if "none" in parts:
        if len(parts) > 1:
            raise argparse.ArgumentTypeError(f"'{text}': 'none' hides nothing and cannot be combined with an effect")
        return "none"
    return "+".join(e for e in REGISTRY if e in parts)


def p75(values):
    v = np.asarray(values, dtype=float)
    return float(np.percentile(v, 75)) if v.size else 0.0


def lowpass_decimate(x, nsub, mode):
    """x sampled at FS*nsub (axis 0) -> FS. 'antialias': zero-phase Hann-windowed
    sinc at 0.4 FS before taking every nsub-th value; 'instant': just take it."""
    if mode == "antialias" and nsub > 1:
        fc = 0.4 * FS / (FS * nsub)  # cycles per sub-sample
        half = 6 * nsub
        k = np.arange(-half, half + 1)
        h = 2 * fc * np.sinc(2 * fc * k) * (0.5 + 0.5 * np.cos(np.pi * k / (half + 1)))
        h /= h.sum()
        pad = np.concatenate([np.repeat(x[:1], half, axis=0), x, np.repeat(x[-1:], half, axis=0)])
        y = np.apply_along_axis(lambda c: np.convolve(c, h, mode="valid"), 0, pad)
        return y[::nsub]
    return x[::nsub]


def demand_ratio(effect, rec, lin_tr, s, truth):
    """Largest (linear demand at input scale s) / (threshold) over the ends or joints."""
    if effect == "perimeter-pounding":
        return max(p * s / g for p, g in zip(lin_tr["peak_toward"], rec["gaps_mm"]))
    if effect == "perimeter-friction":
        ka = [truth["perimeter"]["K_along"] * f for f in truth["perimeter"]["along_factors"]]
        return max(p * s * k / f for p, k, f in zip(lin_tr["peak_abs"], ka, rec["slip_forces_N"]))
    if effect == "connection-hysteresis":
        jp = np.asarray(lin_tr["joint_peak"]) * s
        y = rec["yield_forces_N"]
        return float(max(np.max(jp[:, 0] / np.asarray(y["axial_x"])), np.max(jp[:, 1] / np.asarray(y["transverse_y"]))))
    return 0.0


def size_effect(effect, frac, shape, erng, lin_tr, s, on_shaken, n_ends, dirs, truth):
    """One hidden effect's thresholds from the linear strong-run demand (s: its input
    scale): a record for truth.json and the per-end (perimeter) or per-joint values."""
    rec = {}
    if effect == "perimeter-pounding":
        dem = p75([lin_tr["peak_toward"][k] * s for k in on_shaken])
        mean = frac * dem
        per = [mean * (1 + shape["gap_scatter"] * erng.uniform(-1, 1)) for _ in range(n_ends)]
        rec.update({"linear_demand_mm": dem, "gap_mean_mm": mean, "gaps_mm": per})
    elif effect == "perimeter-friction":
        ka = [truth["perimeter"]["K_along"] * f for f in truth["perimeter"]["along_factors"]]
        dem = p75([lin_tr["peak_abs"][k] * s * ka[k] for k in on_shaken])
        mean = frac * dem
        per = [mean * (1 + shape["slip_scatter"] * erng.uniform(-1, 1)) for _ in range(n_ends)]
        rec.update({"linear_demand_N": dem, "slip_force_mean_N": mean, "slip_forces_N": per})
    else:
        jp = np.asarray(lin_tr["joint_peak"]) * s
        dem = [p75(jp[:, 0]), p75(jp[:, 1])]
        measured = list(dem)
        # a direction the table does not shake carries only parasitic forces: its
        # yield force is the shaken direction's scaled by the joint stiffnesses
        # (the same yield displacement), not a fraction of those small forces
        kj = truth["joint_main_cross"]
        if dirs == "x":
            dem[1] = dem[0] * kj["transverse"] / kj["axial"]
        elif dirs == "y":
            dem[0] = dem[1] * kj["axial"] / kj["transverse"]
        per = [[frac * dem[d] * (1 + shape["yield_scatter"] * erng.uniform(-1, 1)) for _ in range(len(jp))]
               for d in (0, 1)]
        rec.update({"linear_demand_N": {"axial_x": dem[0], "transverse_y": dem[1]},
                    "linear_demand_p75_measured_N": {"axial_x": measured[0], "transverse_y": measured[1]},
                    "yield_force_mean_N": {"axial_x": frac * dem[0], "transverse_y": frac * dem[1]},
                    "yield_forces_N": {"axial_x": per[0], "transverse_y": per[1]}})
    return rec, per


EVENT_KEY = {"perimeter-pounding": "contact_events", "perimeter-friction": "slip_events",
             "connection-hysteresis": "yield_events"}


def linear_below(effect, shape, rec, lin_tr, s, truth):
    if effect == "perimeter-friction" and shape["law"] != "steel01":
        return False
    return demand_ratio(effect, rec, lin_tr, s, truth) < 0.9


def fmt(v):
    return "" if v is None else f"{v:.6g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seed", type=int)
    ap.add_argument("--out", required=True)
    ap.add_argument("--effect", type=effect_set, metavar="none|EFFECT[+EFFECT...]",
                    help="hide this cause (default: drawn from the seed); several effects joined by '+': "
                         + ", ".join(REGISTRY))
    ap.add_argument("--strength", choices=list(STRENGTHS))
    ap.add_argument("--plan", help="LXxLY in metres, e.g. 2.4x3.6 (default: drawn)")
    ap.add_argument("--dry-run", action="store_true", help="print the draws that need no simulation and stop")
    a = ap.parse_args()
    t_start = time.time()
    rng = np.random.default_rng(a.seed)

    # --- what is hidden: a balanced rotation by seed (any 12 consecutive seeds hold
    # each cause 3 times, each effect once at each strength); the two draws are
    # still taken so that the stream below does not depend on the rotation
    rng.choice(EFFECTS), rng.choice(list(STRENGTHS))
    effect = EFFECTS[(a.seed - 1) % 4]
    strength = list(STRENGTHS)[((a.seed - 1) // 4) % 3]
    if a.effect:
        effect = a.effect
    if a.strength:
        strength = a.strength
    if effect == "none":
        strength = "-"
    effects = [] if effect == "none" else effect.split("+")  # in REGISTRY order
    combo = len(effects) > 1

    # --- plan
    small = [2.4, 3.0, 3.6, 4.2, 4.8]
    big = small + [5.4, 6.0]
    if rng.random() < 0.8:
        lx, ly = float(rng.choice(small)), float(rng.choice(small))
    else:
        lx, ly = float(rng.choice(big)), float(rng.choice(big))
    if a.plan:
        m = re.fullmatch(r"([0-9.]+)x([0-9.]+)", a.plan)
        if not m:
            sys.exit(f"campaign.py: --plan {a.plan}: expected LXxLY, e.g. 2.4x3.6")
        lx, ly = float(m.group(1)), float(m.group(2))
        for v in (lx, ly):
            if v < 1.2 or abs(v / 0.6 - round(v / 0.6)) > 1e-9:
                sys.exit(f"campaign.py: --plan {a.plan}: sides must be multiples of 0.6 m, at least 1.2 m")

    truth = T.draw_truth(rng, lx, ly, force_springs=("connection-hysteresis" in effects))
    grid = T.Grid(lx, ly)

    # --- runs: shaken direction(s), sweep, amplitudes
    dirs = str(rng.choice(["x", "y", "xy"], p=[0.35, 0.35, 0.3]))
    sw = {"f_start_hz": T.u(rng, 12, 18), "f_end_hz": T.u(rng, 0.8, 1.5), "taper_s": T.u(rng, 0.5, 1.5),
          "y_phase_rad": T.u(rng, 0, 2 * math.pi), "y_ratio": T.u(rng, 0.6, 1.0)}
    target_mm = T.u(rng, 3.0, 10.0)  # linear strong-run perimeter demand (75th percentile of the ends)
    ratios = {"weak": T.u(rng, 0.08, 0.15), "moderate": T.u(rng, 0.35, 0.6), "strong": 1.0}
    input_units = str(rng.choice(["m/s2", "g"]))
    input_noise = T.u(rng, 0.0, 0.004)  # m/s2
    nsub_draw = int(rng.choice([3, 4]))
    nsub = nsub_draw if "perimeter-pounding" in effects else 2
    daq = str(rng.choice(["antialias", "instant"]))

    # --- sensors: 3-6 at distinct grid nodes (not corners), >= 1 displacement
    shaken = [d for d in "xy" if d in dirs]
    ns = int(rng.integers(3, 7))
    ndisp = 1 if rng.random() < 0.7 or ns < 4 else 2
    cand = [(i, j) for i in range(grid.nx + 1) for j in range(grid.ny + 1) if not grid.corner(i, j)]
    # prefer interior nodes: boundary nodes only when drawn with low odds
    weights = np.array([0.3 if grid.boundary(i, j) else 1.0 for i, j in cand])
    pick = rng.choice(len(cand), size=ns, replace=False, p=weights / weights.sum())
    sensors = []
    for k, c in enumerate(pick):
        i, j = cand[int(c)]
        kind = "displacement" if k < ndisp else "acceleration"
        d = shaken[0] if len(shaken) == 1 else str(rng.choice(shaken))
        if kind == "displacement":
            units = "mm" if rng.random() < 0.8 else "m"
            noise = T.u(rng, 0.03, 0.07)  # mm
            offset = T.u(rng, -0.1, 0.1)  # mm
            sid = f"D{k + 1}"
        else:
            units = str(rng.choice(["m/s2", "g"]))
            noise = T.u(rng, 0.01, 0.03)  # m/s2
            offset = T.u(rng, -0.02, 0.02)  # m/s2
            sid = f"A{k + 1}"
        sensors.append({"id": sid, "kind": kind, "i": i, "j": j, "x_m": round(i * 0.6, 3), "y_m": round(j * 0.6, 3),
                        "direction": d, "units": units, "noise_std": noise, "offset": offset,
                        "noise_units": "mm" if kind == "displacement" else "m/s2"})
    missing_p = 0.001
    std_hz = [T.u(rng, 0.02, 0.05) for _ in range(6)]
    modal_noise = rng.standard_normal(6)
    gap_nominal_factor = T.u(rng, 0.85, 1.15)
    noise_seed = int(rng.integers(1, 2**31))
    # last: the effects' forms do not shift the other draws (several: one after the other, in REGISTRY order)
    shapes = {e: T.draw_effect_shape(rng, e) for e in effects}
    shape = shapes if combo else (shapes[effect] if effects else {})
    shape_seed = int(rng.integers(1, 2**31))

    if a.dry_run:
        print(json.dumps({"seed": a.seed, "cause": effect, "strength": strength, "plan_m": [lx, ly],
                          "directions": dirs, "connections": truth["connections"], "daq": daq,
                          "integration_substeps_per_sample": nsub, "target_linear_strong_demand_mm": target_mm,
                          "member_mass_form": truth["member_mass_form"], "rod_top": truth["rod_top"],
                          "damping": truth["damping"], "K_along": truth["perimeter"]["K_along"],
                          "K_across": truth["perimeter"]["K_across"], "sensors": [(s["id"], s["x_m"], s["y_m"],
                          s["direction"], s["units"]) for s in sensors], "effect_shape": shape}))
        return

    name = os.path.basename(os.path.normpath(a.out))
    if not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        name = f"bench-{a.seed}"
    out = os.path.abspath(a.out)
    parent = os.path.dirname(out)
    os.makedirs(parent, exist_ok=True)
    T.Model.log_path = os.path.join(parent, f"{name}.opensees.log")

    # --- the linear truth: eigen, damping, pre-simulation of the strong run at unit peak
    lin = T.Model(truth)
    for nm in (24, 48, 96):
        modes = lin.eigen(nm)
        horiz = [m_ for m_ in modes if m_["horizontal_share"] > 0.5]
        if len(horiz) >= 8:
            break
    D = truth["damping"]
    i1 = min(D["anchor_first"], len(horiz)) - 1
    i2 = min(i1 + D["anchor_gap"], len(horiz) - 1)
    while i2 < len(horiz) - 1 and horiz[i2]["f_hz"] < 1.05 * horiz[i1]["f_hz"]:
        i2 += 1
    w1, w2 = 2 * math.pi * horiz[i1]["f_hz"], 2 * math.pi * horiz[i2]["f_hz"]
    z = D["zeta"]
    alpha_m = 2 * z * w1 * w2 / (w1 + w2)
    beta_k = 2 * z / (w1 + w2)
    D.update({"anchor_modes": [horiz[i1]["mode"], horiz[i2]["mode"]],
              "anchor_hz": [horiz[i1]["f_hz"], horiz[i2]["f_hz"]], "alpha_m": alpha_m, "beta_k": beta_k})
    lin.set_damping(alpha_m, beta_k, D["tangent"])

    # --- inputs (unit peak, m/s2); the sweep starts above the third horizontal mode
    sw["f_start_drawn_hz"] = sw["f_start_hz"]
    sw["f_start_hz"] = min(25.0, max(sw["f_start_hz"], 1.15 * horiz[min(2, len(horiz) - 1)]["f_hz"]))
    n = int(round(DURATION * FS))
    dt = 1.0 / FS
    base = sweep(n, dt, sw["f_start_hz"], sw["f_end_hz"], sw["taper_s"])
    unit = {"x": base if "x" in dirs else None,
            "y": (sweep(n, dt, sw["f_start_hz"], sw["f_end_hz"], sw["taper_s"], sw["y_phase_rad"]) * sw["y_ratio"]
                  if dirs == "xy" else (base if dirs == "y" else None))}


    sensor_nodes = [lin.grid[(s["i"], s["j"])] for s in sensors]
    mm = lambda v: None if v is None else v * 1000.0  # m/s2 -> mm/s2
    t0 = time.time()
    try:
        lin_disp, lin_acc, lin_tr = lin.simulate(mm(unit["x"]), mm(unit["y"]), dt, nsub, sensor_nodes, track="all",
                                                 linear=True)
    except T.SimulationError as e:
        sys.exit(f"campaign.py: seed {a.seed}: linear pre-simulation: {e}")
    t_pre = time.time() - t0
    end_axes = [e[2] for e in grid.ends]
    on_shaken = [k for k, ax in enumerate(end_axes) if "xy"[ax] in dirs]
    demand_unit = p75([lin_tr["peak_toward"][k] for k in on_shaken])
    scale = target_mm / demand_unit  # m/s2 of strong-run peak input
    scale_limited = min(max(scale, 0.02 * 9.80665), 0.5 * 9.80665)
    amp = {r: scale_limited * ratios[r] for r in ratios}

    # --- each effect's strength from the linear strong-run demand (several: each as it would be
    # alone, its scatter drawn after the previous one's from the same stream)
    frac = STRENGTHS.get(strength)
    erng = np.random.default_rng(shape_seed)
    effect_model = None
    eff_record = {"cause": effect, "strength": strength}
    recs = {}
    if effects:
        s = amp["strong"]
        parts = []
        for e in effects:
            rec = {"cause": e, "strength": strength} if combo else eff_record
            rec.update({"fraction_of_linear_demand": frac, "shape": shapes[e]})
            sized, per = size_effect(e, frac, shapes[e], erng, lin_tr, s, on_shaken, len(grid.ends), dirs, truth)
            rec.update(sized)
            recs[e] = rec
            parts.append({"cause": e, "shape": shapes[e], "per_end": per if e != "connection-hysteresis" else None,
                          "per_joint": per if e == "connection-hysteresis" else None})
        if combo:
            eff_record.update({"fraction_of_linear_demand": frac, "causes": effects,
                               "effects": [recs[e] for e in effects]})
            effect_model = {"cause": effect, "parts": parts}
            # every hidden effect must act in the strong run: its linear demand reaches 0.9
            # of its threshold (by construction it does, as for a single effect; refuse if not)
            quiet = [e for e in effects if linear_below(e, shapes[e], recs[e], lin_tr, s, truth)]
            if quiet:
                sys.exit(f"campaign.py: seed {a.seed}: {effect}: {', '.join(quiet)} would not act in the strong run "
                         f"(linear demand below 0.9 of every threshold: "
                         f"{', '.join(f'{demand_ratio(e, recs[e], lin_tr, s, truth):.3f}' for e in quiet)}); "
                         f"nothing written")
        else:
            effect_model = parts[0]

    # --- the three runs
    run_names = ["weak", "moderate", "strong"]
    results = {}
    timings = {"linear_presimulation_s": t_pre}
    track = ("all" if "connection-hysteresis" in effects else "perimeter") if effects else None
    # several effects: the strong run first, so that one that does not act stops the campaign early
    for r in (["strong", "weak", "moderate"] if combo else run_names):
        s = amp[r]
        if effect == "none":
            results[r] = {"disp": lin_disp * s, "acc": lin_acc * s, "events": None,
                          "peak_toward_max_mm": max(lin_tr["peak_toward"]) * s}
            continue
        # a run whose linear demand stays below 0.9 of every end's or connection's
        # threshold is exactly linear (these laws are elastic below it): scale the
        # pre-simulation instead of integrating it again (not for the rounded Steel02)
        ratio = {e: demand_ratio(e, recs[e], lin_tr, s, truth) for e in effects}
        if all(linear_below(e, shapes[e], recs[e], lin_tr, s, truth) for e in effects):
            results[r] = {"disp": lin_disp * s, "acc": lin_acc * s, "peak_toward_max_mm": max(lin_tr["peak_toward"]) * s,
                          "events": {"linear_by_demand": True, "contact_events": 0, "slip_events": 0,
                                     "yield_events": 0, "rel_change_accel_vs_linear": 0.0,
                                     "rel_change_disp_vs_linear": 0.0,
                                     "peak_perimeter_mm": max(lin_tr["peak_abs"]) * s,
                                     "demand_over_threshold_max": max(ratio.values())}}
            if combo:
                results[r]["events"]["demand_over_threshold_by_effect"] = ratio
            timings[f"{r}_run_s"] = 0.0
            continue
        t0 = time.time()
        mdl = T.Model(truth, effect_model)
        mdl.set_damping(alpha_m, beta_k, D["tangent"])
        nodes = [mdl.grid[(q["i"], q["j"])] for q in sensors]
        try:
            dsp, acc, tr = mdl.simulate(mm(unit["x"] * s if unit["x"] is not None else None),
                                        mm(unit["y"] * s if unit["y"] is not None else None), dt, nsub, nodes,
                                        track=track)
        except T.SimulationError as e:
            sys.exit(f"campaign.py: seed {a.seed}: {effect} run '{r}': {e}")
        timings[f"{r}_run_s"] = time.time() - t0
        lin_ref = lin_acc * s
        change = float(np.linalg.norm(acc - lin_ref) / max(np.linalg.norm(lin_ref), 1e-12))
        dchange = float(np.linalg.norm(dsp - lin_disp * s) / max(np.linalg.norm(lin_disp * s), 1e-12))
        ev = {k: tr[k] for k in ("contact_events", "contact_samples", "slip_events", "slip_samples",
                                 "yield_events", "yield_samples")}
        ev.update({"linear_by_demand": False, "demand_over_threshold_max": max(ratio.values()),
                   "halved_steps": mdl.halvings, "newton_steps": mdl.newton_steps, "retried_steps": mdl.retried, "rel_change_accel_vs_linear": change,
                   "rel_change_disp_vs_linear": dchange,
                   "peak_perimeter_mm": max(tr["peak_abs"]), "max_residual_mm": max(abs(v) for v in tr["residual"])})
        results[r] = {"disp": dsp, "acc": acc, "events": ev, "peak_toward_max_mm": max(tr["peak_toward"])}
        if combo:
            ev["demand_over_threshold_by_effect"] = ratio
            ev["linear_by_demand_by_effect"] = {e: linear_below(e, shapes[e], recs[e], lin_tr, s, truth)
                                                for e in effects}
            if r == "strong":
                idle = [e for e in effects if ev[EVENT_KEY[e]] == 0]
                if idle:
                    sys.exit(f"campaign.py: seed {a.seed}: {effect}: {', '.join(idle)} did not act in the strong run "
                             f"({', '.join(f'0 {EVENT_KEY[e]}' for e in idle)}, though the linear demand reaches "
                             f"{', '.join(f'{ratio[e]:.3f}' for e in idle)} of the threshold); nothing written")

    # --- nominal gap a lab would write
    if "perimeter-pounding" in effects:
        nominal_gap = round(recs["perimeter-pounding"]["gap_mean_mm"] * gap_nominal_factor, 1)
    else:
        nominal_gap = round(max(19.0, 1.5 * max(results[r]["peak_toward_max_mm"] for r in run_names)), 1)

    # --- measurements
    nrng = np.random.default_rng(noise_seed)
    tmp = tempfile.mkdtemp(prefix=f".{name}.", dir=parent)
    try:
        os.makedirs(os.path.join(tmp, "runs"))
        tt = np.arange(n) * dt
        gunit = 9.80665
        run_meta = []
        for k, r in enumerate(run_names, start=1):
            s = amp[r]
            cols = ["t"]
            data = [[f"{v:.3f}" for v in tt]]
            ag = {}
            for d in "xy":
                if unit[d] is None:
                    continue
                ag[d] = unit[d] * s  # m/s2, clean
                meas = ag[d] + input_noise * nrng.standard_normal(n)
                if input_units == "g":
                    meas = meas / gunit
                cols.append(f"base_a{d}")
                data.append([fmt(v) for v in meas])
            disp = lowpass_decimate(results[r]["disp"], nsub, daq)
            acc = lowpass_decimate(results[r]["acc"], nsub, daq)
            for q, sen in enumerate(sensors):
                di = "xy".index(sen["direction"])
                if sen["kind"] == "displacement":
                    v = disp[:, q, di] + sen["offset"] + sen["noise_std"] * nrng.standard_normal(n)
                    if sen["units"] == "m":
                        v = v / 1000.0
                else:
                    v = acc[:, q, di] / 1000.0 + (ag[sen["direction"]] if sen["direction"] in ag else 0.0)
                    v = v + sen["offset"] + sen["noise_std"] * nrng.standard_normal(n)
                    if sen["units"] == "g":
                        v = v / gunit
                miss = nrng.random(n) < missing_p
                cols.append(sen["id"])
                data.append(["" if miss[i] else fmt(v[i]) for i in range(n)])
            fn = f"runs/run{k}.csv"
            with open(os.path.join(tmp, fn), "w") as f:
                f.write(",".join(cols) + "\n")
                for row in zip(*data):
                    f.write(",".join(row) + "\n")
            pga = max(float(np.max(np.abs(v))) for v in ag.values())
            run_meta.append({"id": f"run{k}", "file": fn, "level": r, "peak_input_m_s2": pga,
                             "peak_input_g": pga / gunit, "role": "validation" if r == "strong" else "calibration",
                             "columns": cols})
        # bundle.toml
        L = ["format = \"ceiling-measured/1\"", f"name = \"{name}\"",
             f"description = \"bench-specimen second truth family, seed {a.seed}: three sine sweeps in {dirs}\"", "",
             "[structure]", f"length_x_m = {lx}", f"length_y_m = {ly}", "module_m = 0.6", "main_tee_spacing_m = 1.2",
             "hanger_spacing_m = 1.2", "hanger_length_m = 1.0", "panel_mass_kg = 1.2", "layers = 1",
             "boundary = \"semi-free\"", f"nominal_gap_mm = {nominal_gap}",
             "wall_members = true  # main tees on x = 0 (and x = Lx on the 1.2 m lines), cross tees on y = 0, Ly",
             f"hanger_offset_m = {round(truth['rod_first_row_m'] % 1.2, 6)}  # first row of rods from y = 0", ""]
        for sen in sensors:
            L += ["[[sensors]]", f"id = \"{sen['id']}\"", f"kind = \"{sen['kind']}\"", f"x_m = {sen['x_m']}",
                  f"y_m = {sen['y_m']}", f"direction = \"{sen['direction']}\"", f"units = \"{sen['units']}\"", ""]
        for rm in run_meta:
            L += ["[[runs]]", f"id = \"{rm['id']}\"", f"file = \"{rm['file']}\"",
                  f"description = \"exponential sine sweep {sw['f_start_hz']:.1f} -> {sw['f_end_hz']:.1f} Hz, "
                  f"{DURATION:.0f} s, peak {rm['peak_input_g']:.4f} g, {dirs}\""]
            if "x" in dirs:
                L.append("input_x = \"base_ax\"")
            if dirs in ("y", "xy"):
                L.append("input_y = \"base_ay\"")
            L += [f"input_units = \"{input_units}\"", f"role = \"{rm['role']}\"", ""]
        with open(os.path.join(tmp, "bundle.toml"), "w") as f:
            f.write("\n".join(L))
        # modal.csv: the first six horizontal modes of the truth, with noise
        modal = []
        for k in range(min(6, len(horiz))):
            fm = horiz[k]["f_hz"] + std_hz[k] * modal_noise[k]
            modal.append({"freq_hz": fm, "std_hz": std_hz[k], "truth_hz": horiz[k]["f_hz"],
                          "truth_mode": horiz[k]["mode"]})
        modal.sort(key=lambda q: q["freq_hz"])  # a lab lists what it identified in order
        with open(os.path.join(tmp, "modal.csv"), "w") as f:
            f.write("mode,freq_hz,std_hz\n")
            for k, q in enumerate(modal, start=1):
                q["mode"] = k
                f.write(f"{k},{q['freq_hz']:.4f},{q['std_hz']:.3f}\n")
        if os.path.exists(out):
            shutil.rmtree(out)
        os.chmod(tmp, 0o755)
        os.rename(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise

    timings["total_s"] = time.time() - t_start
    doc = {
        "format": "bench-specimen-truth/1", "seed": a.seed, "name": name, "bundle": out,
        "cause": effect, "strength": strength, "effect": eff_record,
        "plan_m": [lx, ly], "directions": dirs, "sweep": sw, "target_linear_strong_demand_mm": target_mm,
        "level_ratios": ratios, "input_scale_m_s2_unlimited": scale, "runs": run_meta, "input_units": input_units,
        "input_noise_m_s2": input_noise, "integration_substeps_per_sample": nsub, "daq": daq,
        "sensors": sensors, "missing_reading_probability": missing_p, "nominal_gap_mm_written": nominal_gap,
        "truth_mass_t": lin.total_mass_t,
        "natural_frequencies_hz": [m_["f_hz"] for m_ in modes[:8]],
        "modes": modes,
        "horizontal_frequencies_hz": [m_["f_hz"] for m_ in horiz[:8]],
        "first6_truth_hz": [m_["f_hz"] for m_ in horiz[:6]],
        "modal_csv": modal,
        "modal_note": "modal.csv lists the first six modes whose kinetic energy is mostly horizontal "
                      "(a lab identifies them from horizontal sensors); vertical modes are in 'modes'",
        "linear_demand_per_unit_input": {"perimeter_p75_toward_wall_mm": demand_unit},
        "events": {r: results[r]["events"] for r in run_names},
        "modelling": truth, "timings_s": timings,
    }
    with open(os.path.join(parent, f"{name}.truth.json"), "w") as f:
        json.dump(doc, f, indent=1)
    ev = doc["events"]
    summ = ""
    if effects:
        summ = ", " + ", ".join(f"{r} " + " ".join(f"{ev[r][EVENT_KEY[e]]} {EVENT_KEY[e].replace('_', ' ')}"
                                                   for e in effects)
                                + f" (accel change {ev[r]['rel_change_accel_vs_linear']:.3f})" for r in run_names)
    print(f"{name}: seed {a.seed}, {lx} x {ly} m, {effect} {strength}, shaken {dirs}, "
          f"f1..6 {' '.join(f'{m_['f_hz']:.2f}' for m_ in horiz[:6])} Hz, strong peak {amp['strong'] / 9.80665:.3f} g"
          f"{summ}; {timings['total_s']:.1f} s")


if __name__ == "__main__":
    main()
