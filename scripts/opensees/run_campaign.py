#!/usr/bin/env python3
"""Run every exported run model of a synthetic campaign in OpenSees.

    python3.12 scripts/opensees/run_campaign.py MDIR [--osjson DIR] [--runs ID,...]
                                                [--variant NAME[,NAME...]] [--variant-seed S]
    python3.12 scripts/opensees/run_campaign.py --self-check

MDIR is what `ceilfarm synth SPEC.toml --export-models MDIR` wrote: per run
`<run>.json` (a `ceiling-fe-model` file whose transient stanza lists one base
record per shaken direction under `excitations`), its records, and the sensor
sidecar `<run>.sensors.json`; `modal.json` when the campaign has modal data.
This script writes, for `ceilfarm synth SPEC.toml --histories MDIR`:

* `<run>.history.csv`: header `t_s`, then the model's recorder columns (mm/s^2
  absolute acceleration, mm displacement relative to the base), one row per
  output step from t = 0;
* `modal.json`: `freq_hz`, the lowest `n_modes` OpenSees frequencies (Hz);
* `simulator.json`: `{"simulator": "opensees", ...}` with CPU times per run
  and, where ceilfarm's own history `<run>.ceilfarm.csv` lies beside, the
  NRMSE of every bundle sensor between the two codes.

The model is built by the reference driver `osjson.py`
(`<repo>/../shared/verification/opensees`, or --osjson, or the environment
variable CEILFARM_OSJSON_DIR). Everything after the build is done here: one
`UniformExcitation` pattern per shaken direction, Rayleigh damping on the
initial stiffness (osjson.apply_damping; on the last committed tangent under
the damping-tangent variant), Newmark with Newton and the
NormDispIncr test at osjson.setup_transient's tolerance. A step that does not
converge is halved, up to 6 times (dt/64, as ceilfarm does), and at dt/64 tried
once more with Newton on the initial tangent (for materials whose reported
tangent does not follow their path); if that fails too the run's history stops
there, the failure is reported, and the exit status is 1.

NRMSE of a sensor = RMS(OpenSees - ceilfarm) / RMS(ceilfarm), over the run.

--variant changes the model's form before OpenSees builds it (variants.py:
every name in its docstring, e.g. gap-scatter, friction-smooth, pinching-flag),
the same way in every run and in the modal model; the changed model is written
as `<run>.variant.json` beside the exported one (which is left as it is, since
ceilfarm checks it) and simulator.json says under `variants` what each variant
did to each model, or that its target is absent.
"""
import argparse
import csv
import inspect
import json
import math
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
MAX_HALVINGS = 6
sys.path.insert(0, HERE)
import variants  # noqa: E402


def import_osjson(explicit=None):
    """Import the reference model builder osjson from the first folder that has it."""
    candidates = [explicit, os.environ.get("CEILFARM_OSJSON_DIR"),
                  os.path.join(REPO, "..", "shared", "verification", "opensees")]
    for c in candidates:
        if c and os.path.isfile(os.path.join(c, "osjson.py")):
            sys.path.insert(0, os.path.abspath(c))
            import osjson
            return osjson
    sys.exit("run_campaign: osjson.py not found in %s; pass --osjson DIR"
             % [c for c in candidates if c])


def allow_opensees_materials(osjson):
    """Lets a variant give a material as an OpenSees command,
    {"type": "OpenSees", "cmd": [name, arg, ...]}; osjson builds the others."""
    if "OpenSees" in osjson.MATERIAL_KEYS:
        return
    osjson.MATERIAL_KEYS["OpenSees"] = ["cmd"]
    build = osjson.opensees_material

    def material(ops, mat):
        if mat["type"] == "OpenSees":
            ops.uniaxialMaterial(mat["cmd"][0], mat["id"], *mat["cmd"][1:])
        else:
            build(ops, mat)
    osjson.opensees_material = material


def newton_settings(osjson):
    """Tolerance and iteration limit of osjson.setup_transient (its defaults)."""
    p = inspect.signature(osjson.setup_transient).parameters
    return p["tol"].default, p["max_iter"].default


def excitations(an):
    """The base records of a transient stanza: `excitations`, else the single `excitation`."""
    ex = an.get("excitations") or [an["excitation"]]
    dofs = [e["dof"] for e in ex]
    if len(set(dofs)) != len(dofs):
        raise ValueError("two excitations in the same dof %s" % dofs)
    return ex


def apply_damping(m, ops, osjson):
    """Rayleigh damping as osjson applies it (initial stiffness), or on the
    last committed tangent where the damping-tangent variant (or a model's
    committed_share s) says so: (1 - s) betaK initial + s betaK committed."""
    d = m.get("damping")
    if d and d.get("stiffness") == "committed":
        assert d["type"] == "rayleigh", d["type"]
        s = float(d.get("committed_share", 1.0))
        assert 0.0 <= s <= 1.0, s
        # alphaM, betaK(current)=0, betaK(initial), betaK(committed)
        ops.rayleigh(d["alphaM"], 0.0, (1.0 - s) * d["betaK"], s * d["betaK"])
        return
    osjson.apply_damping(m, ops)


def setup(m, ops, osjson):
    """Damping, one UniformExcitation per record, Newmark + Newton; returns {dof: (dt, acc)}."""
    an = m["analysis"]
    assert an["type"] == "transient", an["type"]
    apply_damping(m, ops, osjson)
    ground = {}
    for k, exc in enumerate(excitations(an), start=1):
        assert exc["type"] == "uniform_base_acceleration", exc["type"]
        dt_rec, acc = osjson.read_record(m, exc)
        scale = exc.get("scale", 1.0)
        ops.timeSeries("Path", k, "-dt", dt_rec, "-values", *acc, "-factor", scale)
        ops.pattern("UniformExcitation", k, exc["dof"], "-accel", k)
        ground[exc["dof"]] = (dt_rec, [a * scale for a in acc])
    integ = an["integrator"]
    assert integ["type"] == "Newmark", integ
    tol, max_iter = newton_settings(osjson)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("UmfPack")
    ops.test("NormDispIncr", tol, max_iter, 0)
    ops.algorithm("Newton")
    ops.integrator("Newmark", integ["gamma"], integ["beta"])
    ops.analysis("Transient")
    return ground


def column_names(recs):
    out = []
    for r in recs:
        if "name" in r:
            out.append(r["name"])
        elif "node" in r:
            out.append("n%d_dof%d_%s" % (r["node"], r["dof"], r["response"]))
        else:
            out.append("e%d_%s" % (r["element"], r["response"]))
    return out


def sample(ops, osjson, recs, ground, t):
    """One output row at time t: t, then every recorder."""
    ag = {dof: osjson.ground_accel(acc, dt, t) for dof, (dt, acc) in ground.items()}
    row = [t]
    for r in recs:
        resp = r["response"]
        if "node" in r:
            if resp == "disp":
                row.append(ops.nodeDisp(r["node"], r["dof"]))
            elif resp == "vel":
                row.append(ops.nodeVel(r["node"], r["dof"]))
            elif resp == "accel_abs":
                row.append(ops.nodeAccel(r["node"], r["dof"]) + ag.get(r["dof"], 0.0))
            else:
                raise ValueError("node response %r" % resp)
        elif resp == "deformation":
            row.append(ops.eleResponse(r["element"], "deformation")[0])
        elif resp == "force":
            row.append(ops.eleResponse(r["element"], "basicForce")[0])
        else:
            raise ValueError("element response %r" % resp)
    return row


def advance(ops, dt, depth, stats):
    """One step of dt; on failure two halves, recursively, up to MAX_HALVINGS
    deep; at the deepest level, Newton on the initial tangent
    (ModifiedNewton -initial: a material whose reported tangent does not
    follow its own path, as OpenSees Hysteretic's after unloading, stalls
    Newton at any step size), then Newton again."""
    if ops.analyze(1, dt) == 0:
        stats["substeps"] += 1
        return True
    if depth >= MAX_HALVINGS:
        ops.algorithm("ModifiedNewton", "-initial")
        ok = ops.analyze(1, dt) == 0
        ops.algorithm("Newton")
        stats["initial_tangent_steps"] += int(ok)
        stats["substeps"] += int(ok)
        return ok
    stats["halvings"] += 1
    return advance(ops, dt / 2, depth + 1, stats) and advance(ops, dt / 2, depth + 1, stats)


def variant_model(path, osjson, names, seed):
    """The model at path with variants applied, written as <stem>.variant.json;
    returns (that path, report). No variants: (path, None)."""
    if not names:
        return path, None
    with open(path) as f:
        m, report = variants.apply(json.load(f), names, seed)
    out = path[: -len(".json")] + ".variant.json"
    with open(out, "w") as f:
        json.dump(m, f, indent=1)
        f.write("\n")
    osjson.load_model(out)
    return out, report


def run_model(path, osjson, ops):
    """Builds and integrates one model; returns (columns, rows, report)."""
    m = osjson.load_model(path)
    osjson.build_opensees(m, ops)
    an = m["analysis"]
    w0, c0 = time.perf_counter(), time.process_time()
    ground = setup(m, ops, osjson)
    dt, n = an["dt"], an["n_steps"]
    every = an.get("output_every_n_steps", 1)
    recs = an["recorders"]
    rows = [sample(ops, osjson, recs, ground, 0.0)]
    stats = {"substeps": 0, "halvings": 0, "initial_tangent_steps": 0}
    failed = None
    for k in range(1, n + 1):
        if not advance(ops, dt, 0, stats):
            failed = {"step": k, "t_s": (k - 1) * dt,
                      "message": "no convergence of Newton (NormDispIncr) even at dt/%d, "
                                 "nor on the initial tangent" % 2 ** MAX_HALVINGS}
            break
        if k % every == 0:
            rows.append(sample(ops, osjson, recs, ground, k * dt))
    report = {"steps": n, "dt_s": dt, "substeps": stats["substeps"],
              "halvings": stats["halvings"],
              "initial_tangent_steps": stats["initial_tangent_steps"], "failed": failed,
              "wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0}
    return ["t_s"] + column_names(recs), rows, report


def write_csv(path, columns, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        w.writerows([[repr(float(v)) for v in r] for r in rows])


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], [[float(v) for v in r] for r in rows[1:] if r]


def sensor_series(columns, rows, recipe):
    """A bundle sensor from recorder columns: sum of weight x column, times to_bundle."""
    idx = [columns.index(c) for c in recipe["columns"]]
    return [recipe["to_bundle"] * sum(w * r[i] for w, i in zip(recipe["weights"], idx))
            for r in rows]


def nrmse(a, ref):
    n = min(len(a), len(ref))
    if n == 0:
        return float("nan")
    rms_d = math.sqrt(sum((a[k] - ref[k]) ** 2 for k in range(n)) / n)
    rms_r = math.sqrt(sum(v * v for v in ref[:n]) / n)
    return rms_d / rms_r if rms_r > 0 else float("inf")


def compare(mdir, run, side, columns, rows):
    """Per bundle sensor, against ceilfarm's own history if it lies beside:
    NRMSE and both RMS values (bundle units). A sensor whose ceilfarm RMS is
    below 1e-9 of the largest of its kind in the run (e.g. y in an x-only
    run) only ever reads round-off: its NRMSE is None."""
    path = os.path.join(mdir, run + ".ceilfarm.csv")
    if not os.path.isfile(path):
        return None
    cf_cols, cf_rows = read_csv(path)
    rms = lambda v: math.sqrt(sum(x * x for x in v) / max(1, len(v)))
    out, scale = {}, {}
    for s in side["sensors"]:
        os_v, cf_v = sensor_series(columns, rows, s), sensor_series(cf_cols, cf_rows, s)
        out[s["id"]] = {"nrmse": nrmse(os_v, cf_v), "rms_opensees": rms(os_v),
                        "rms_ceilfarm": rms(cf_v), "units": s["bundle_units"]}
        scale[s["kind"]] = max(scale.get(s["kind"], 0.0), rms(cf_v))
    for s in side["sensors"]:
        if out[s["id"]]["rms_ceilfarm"] < 1e-9 * scale[s["kind"]]:
            out[s["id"]]["nrmse"] = None
    return out


def describe_variants(vrep):
    return ", ".join(n if r["applied"] else n + " (absent: no-op)" for n, r in vrep.items())


def describe(cmp):
    parts = []
    for sid, c in cmp.items():
        if c["nrmse"] is None:
            parts.append("%s idle (RMS %.1e vs %.1e %s)" % (sid, c["rms_opensees"], c["rms_ceilfarm"], c["units"]))
        else:
            parts.append("%s %.2e" % (sid, c["nrmse"]))
    return ", ".join(parts)


def modal(mdir, osjson, ops, names=(), seed=0):
    """Adds the OpenSees frequencies to modal.json; returns (f_hz, cpu_s, variant report) or None."""
    path = os.path.join(mdir, "modal.json")
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        md = json.load(f)
    mpath, vrep = variant_model(os.path.join(mdir, md["model"]), osjson, names, seed)
    m = osjson.load_model(mpath)
    osjson.build_opensees(m, ops)
    c0 = time.process_time()
    f_hz = osjson.eigen_hz(ops, md["n_modes"], "-genBandArpack")
    cpu = time.process_time() - c0
    md.update(freq_hz=f_hz, simulator="opensees")
    if names:
        md["variants"] = {"names": list(vrep), "seed": seed}
    with open(path, "w") as f:
        json.dump(md, f, indent=2)
        f.write("\n")
    return f_hz, cpu, vrep


def opensees_version():
    try:
        from importlib.metadata import version
        return version("openseespy")
    except Exception:
        return "unknown"


def run_campaign(mdir, osjson, only=None, names=(), seed=0):
    import openseespy.opensees as ops
    runs = sorted(f[: -len(".sensors.json")] for f in os.listdir(mdir) if f.endswith(".sensors.json"))
    if only:
        missing = [r for r in only if r not in runs]
        if missing:
            sys.exit("run_campaign: %s: no exported run %s (have %s)" % (mdir, missing, runs))
        runs = [r for r in runs if r in only]
    if not runs:
        sys.exit("run_campaign: %s holds no <run>.sensors.json; export with "
                 "`ceilfarm synth SPEC --export-models %s`" % (mdir, mdir))
    summary = {"simulator": "opensees", "openseespy": opensees_version(), "runs": {}}
    if names:
        summary["variants"] = {"names": list(names), "seed": seed, "models": {}}
    status = 0
    for run in runs:
        with open(os.path.join(mdir, run + ".sensors.json")) as f:
            side = json.load(f)
        mpath, vrep = variant_model(os.path.join(mdir, side["model"]), osjson, names, seed)
        if vrep is not None:
            summary["variants"]["models"][os.path.basename(mpath)] = vrep
            print("%s: variants %s" % (run, describe_variants(vrep)), flush=True)
        columns, rows, rep = run_model(mpath, osjson, ops)
        write_csv(os.path.join(mdir, side["history_csv"]), columns, rows)
        rep["nrmse_vs_ceilfarm"] = compare(mdir, run, side, columns, rows)
        summary["runs"][run] = rep
        line = "%s: %d steps, %d halvings, CPU %.2f s" % (run, rep["steps"], rep["halvings"], rep["cpu_s"])
        if rep["failed"]:
            status = 1
            line += "; FAILED at step %(step)d (t = %(t_s)g s): %(message)s" % rep["failed"]
            line += "; %s holds %d of %d rows" % (side["history_csv"], len(rows), side["n_rows"])
        if rep["nrmse_vs_ceilfarm"]:
            line += "; NRMSE vs ceilfarm: " + describe(rep["nrmse_vs_ceilfarm"])
        print(line, flush=True)
    md = modal(mdir, osjson, ops, names, seed)
    if md:
        summary["freq_hz"], summary["eigen_cpu_s"], vrep = md
        if vrep is not None:
            summary["variants"]["modal_model"] = vrep
            with open(os.path.join(mdir, "modal.json")) as f:
                summary["ceilfarm_freq_hz"] = json.load(f).get("ceilfarm_freq_hz")
        print("modal: OpenSees f_hz %s" % ", ".join("%.4f" % f for f in md[0]))
    summary["cpu_s"] = sum(r["cpu_s"] for r in summary["runs"].values())
    with open(os.path.join(mdir, "simulator.json"), "w") as f:
        json.dump(summary, f, indent=2)
        f.write("\n")
    print("total OpenSees CPU %.2f s" % summary["cpu_s"])
    return status


def self_check(osjson):
    """A two-direction oscillator (x and y springs, Rayleigh on both, its own
    sine in each direction) against the exact linear Newmark recurrence."""
    import tempfile
    import openseespy.opensees as ops
    mass, kx, ky, alpha, beta_k, dt, n = 2e-3, 30.0, 55.0, 0.8, 4e-4, 0.01, 300
    rec = {1: [3000.0 * math.sin(2 * math.pi * 2.0 * k * dt) for k in range(n + 1)],
           2: [-1700.0 * math.sin(2 * math.pi * 3.1 * k * dt) for k in range(n + 1)]}
    with tempfile.TemporaryDirectory() as d:
        exc = []
        for dof, acc in rec.items():
            name = "base_%d.csv" % dof
            write_csv(os.path.join(d, name), ["t_s", "ag_mm_s2"],
                      [[k * dt, a] for k, a in enumerate(acc)])
            exc.append({"type": "uniform_base_acceleration", "dof": dof, "record_csv": name,
                        "dt": dt, "npts": n + 1, "scale": 1.0})
        spring = lambda i, dof, mat: {"id": i, "i": 1, "j": 2, "dof": dof, "mat": mat, "rayleigh": True}
        model = {"format": "ceiling-fe-model", "format_version": 1,
                 "units": {"force": "N", "length": "mm", "time": "s", "mass": "t"},
                 "ndm": 3, "ndf": 6, "nodes": [[1, 0, 0, 0], [2, 0, 0, 0]],
                 "fixities": [[1, 1, 1, 1, 1, 1, 1], [2, 0, 0, 1, 1, 1, 1]],
                 "materials": [{"id": 1, "type": "Elastic", "k": kx},
                               {"id": 2, "type": "Elastic", "k": ky}],
                 "springs": [spring(1, 1, 1), spring(2, 2, 2)],
                 "masses": [{"node": 2, "m": [mass, mass, 0, 0, 0, 0]}],
                 "damping": {"type": "rayleigh", "alphaM": alpha, "betaK": beta_k,
                             "stiffness": "initial"},
                 "analysis": {"type": "transient", "excitations": exc,
                              "integrator": {"type": "Newmark", "gamma": 0.5, "beta": 0.25},
                              "dt": dt, "n_steps": n,
                              "recorders": [{"name": "ax", "node": 2, "dof": 1, "response": "accel_abs"},
                                            {"name": "uy", "node": 2, "dof": 2, "response": "disp"},
                                            {"name": "ay", "node": 2, "dof": 2, "response": "accel_abs"},
                                            {"name": "ux", "node": 2, "dof": 1, "response": "disp"}]}}
        path = os.path.join(d, "oscillator.json")
        with open(path, "w") as f:
            json.dump(model, f)
        columns, rows, rep = run_model(path, osjson, ops)
    worst = 0.0
    for dof, k in ((1, kx), (2, ky)):
        u_ref, a_ref = newmark_sdof(mass, alpha * mass + beta_k * k, k, rec[dof], dt)
        for name, ref in (("u" + "xy"[dof - 1], u_ref), ("a" + "xy"[dof - 1], a_ref)):
            got = [r[columns.index(name)] for r in rows]
            err = max(abs(g - r) for g, r in zip(got, ref)) / max(abs(r) for r in ref)
            print("self-check %s: max |OpenSees - Newmark| / peak = %.2e" % (name, err))
            worst = max(worst, err)
    ok = rep["failed"] is None and len(rows) == n + 1 and worst < 1e-6
    print("self-check: %s" % ("ok" if ok else "FAILED"))
    return 0 if ok else 1


def newmark_sdof(m, c, k, ag, dt, gamma=0.5, beta=0.25):
    """Relative displacement and absolute acceleration of m u'' + c u' + k u = -m ag."""
    u, v, a = 0.0, 0.0, 0.0
    us, accs = [0.0], [0.0 + ag[0]]
    keff = k + gamma / (beta * dt) * c + m / (beta * dt * dt)
    for p in (-m * x for x in ag[1:]):
        peff = (p + m * (u / (beta * dt * dt) + v / (beta * dt) + (0.5 / beta - 1) * a)
                + c * (gamma * u / (beta * dt) + (gamma / beta - 1) * v
                       + dt * (gamma / (2 * beta) - 1) * a))
        u1 = peff / keff
        a1 = (u1 - u) / (beta * dt * dt) - v / (beta * dt) - (0.5 / beta - 1) * a
        v = v + dt * ((1 - gamma) * a + gamma * a1)
        u, a = u1, a1
        us.append(u)
        accs.append(a)
    return us, [x + g for x, g in zip(accs, ag)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mdir", nargs="?", help="folder written by ceilfarm synth --export-models")
    ap.add_argument("--osjson", help="folder holding osjson.py")
    ap.add_argument("--runs", help="comma-separated run ids (default: all)")
    ap.add_argument("--variant", help="comma-separated model-form variants (variants.py): "
                    + ", ".join(variants.ORDER))
    ap.add_argument("--variant-seed", type=int, default=0,
                    help="seed of the variants' per-spring factors (default 0)")
    ap.add_argument("--self-check", action="store_true",
                    help="run a two-direction oscillator against the exact Newmark recurrence")
    a = ap.parse_args()
    try:
        names = variants.parse(a.variant)
    except ValueError as e:
        ap.error("--variant: %s" % e)
    osjson = import_osjson(a.osjson)
    allow_opensees_materials(osjson)
    if a.self_check:
        variants.self_check()
        print("variants self-check: ok")
        return self_check(osjson)
    if not a.mdir:
        ap.error("MDIR is required (or --self-check)")
    return run_campaign(a.mdir, osjson, a.runs.split(",") if a.runs else None,
                        names, a.variant_seed)


if __name__ == "__main__":
    sys.exit(main())
