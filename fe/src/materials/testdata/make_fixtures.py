"""Regenerates the OpenSees reference responses of this folder.

Usage (OpenSeesPy 3.8.0.0 on Python >= 3.12):
    python make_fixtures.py ../../../../shared/verification/materials/materials.json
Takes the CJS-A Pinching4 set from the shared fixtures' materials.json, builds the
protocols below (cyclic, and seeded random walks), drives each material with
opensees_drive.py, and writes <name>.csv plus materials.json here.
"""
import json, os, random, subprocess, sys, tempfile
TD = os.path.dirname(os.path.abspath(__file__))
base = json.load(open(sys.argv[1]))['fixtures'][0]['material']
base.pop('id')
def cyc(amps, step):
    d = [0.0]
    for a in amps:
        for t in (a, -a, 0.0):
            x = d[-1]
            n = max(1, int(round(abs(t - x) / step)))
            d += [x + (t - x) * i / n for i in range(1, n + 1)]
    return d
def walk(seed, n, lim, smax):
    r = random.Random(seed); d = [0.0]; v = smax
    for i in range(n):
        if r.random() < 0.04: v = -v
        x = d[-1] + v * r.random()
        if abs(x) > lim: v = -v; x = d[-1] + v * r.random()
        d.append(round(x, 6))
    return d
cases = {}
deg = dict(base, gK=[1.0, 0.2, 0.3, 0.2], gKLim=0.9, gD=[0.5, 0.5, 2.0, 2.0], gDLim=0.5,
           gF=[1.0, 0.0, 1.0, 1.0], gFLim=0.9, gE=10.0)
cases['pinching4_degrading_cycle'] = (dict(deg, dmgType='cycle'), cyc([1, 2, 4, 6, 8, 10, 12, 14, 16, 17], 0.05))
cases['pinching4_degrading_energy'] = (dict(deg, dmgType='energy', gE=2.0), cyc([1, 2, 4, 6, 8, 10, 12, 14, 16, 17], 0.05))
cases['pinching4_degrading_walk'] = (dict(deg, dmgType='energy', gE=3.0), walk(1, 6000, 17.0, 0.3))
cases['pinching4_uforce_branches'] = (dict(deg, dmgType='cycle', rForceP=0.1, uForceP=0.1, rForceN=0.0, uForceN=0.05,
                                           rDispP=0.3, rDispN=0.8), walk(2, 6000, 17.0, 0.4))
cases['pinching4_cjsa_walk'] = (dict(base), walk(3, 8000, 17.0, 0.25))
cases['steel01_walk'] = ({"type": "Steel01", "Fy": 2.0, "E0": 20.0, "b": 0.05}, walk(4, 4000, 6.0, 0.15))
cases['impact_walk'] = ({"type": "Impact", "K1": 300.0, "K2": 100.0, "dy": 0.1, "gap": 13.3}, walk(5, 6000, 20.0, 0.2))
for n, r in [(1.0, 0.0), (2.0, 0.1), (10.0, 0.0)]:
    cases['bouc_wen_n%d_walk' % n] = ({"type": "BoucWen", "Fy": 2.0, "dy": 0.1, "exponent": n, "ratio": r},
                                      walk(10 + int(n), 4000, 1.5, 0.05))
TMP = tempfile.mkdtemp()
index = {}
for name, (mat, d) in cases.items():
    json.dump(mat, open(os.path.join(TMP, 'm.json'), 'w'))
    with open(os.path.join(TMP, 'p.csv'), 'w') as f:
        f.write('step,deformation_mm\n')
        for i, x in enumerate(d): f.write('%d,%r\n' % (i, x))
    subprocess.run([sys.executable, os.path.join(TD, 'opensees_drive.py'), os.path.join(TMP, 'm.json'), os.path.join(TMP, 'p.csv'), '%s/%s.csv' % (TD, name)], capture_output=True)
    index[name] = mat
json.dump(index, open(TD + '/materials.json', 'w'), indent=1)
