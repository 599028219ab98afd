"""Drives one ceilfarm material JSON through a protocol CSV in OpenSees:
testUniaxialMaterial + setStrain (trial and commit) per row; writes
deformation_mm,force_N,tangent_N_per_mm with full precision.
Usage: python opensees_drive.py MATERIAL.json PROTOCOL.csv OUT.csv
"""
import sys, json
import openseespy.opensees as ops
mat = json.load(open(sys.argv[1]))
d = [float(l.split(',')[1]) for l in open(sys.argv[2]).read().split('\n')[1:] if l.strip()]
ops.wipe()
t = mat['type']
if t == 'Pinching4':
    args = []
    for f, dd in zip(mat['ePf'], mat['ePd']): args += [f, dd]
    for f, dd in zip(mat['eNf'], mat['eNd']): args += [f, dd]
    args += [mat['rDispP'], mat['rForceP'], mat['uForceP'], mat['rDispN'], mat['rForceN'], mat['uForceN']]
    args += mat['gK'] + [mat['gKLim']] + mat['gD'] + [mat['gDLim']] + mat['gF'] + [mat['gFLim']] + [mat['gE'], mat['dmgType']]
    ops.uniaxialMaterial('Pinching4', 1, *args)
elif t == 'Steel01':
    ops.uniaxialMaterial('Steel01', 1, mat['Fy'], mat['E0'], mat['b'])
elif t == 'BoucWen':
    # SAP2000 Wen link = OpenSees BoucWen with z in mm: alpha = ratio,
    # ko = Fy/dy, gamma = beta = 0.5/dy^n, Ao = 1, no degradation.
    n, dy = mat['exponent'], mat['dy']
    g = 0.5 / dy ** n
    ops.uniaxialMaterial('BoucWen', 1, mat.get('ratio', 0.0), mat['Fy'] / dy, n, g, g, 1.0, 0.0, 0.0, 0.0, 1e-14, 200)
elif t == 'Impact':
    ops.uniaxialMaterial('ImpactMaterial', 1, mat['K1'], mat['K2'], -mat['dy'], -mat['gap'])
ops.testUniaxialMaterial(1)
with open(sys.argv[3], 'w') as out:
    out.write('deformation_mm,force_N,tangent_N_per_mm\n')
    for x in d:
        ops.setStrain(x)
        out.write('%r,%r,%r\n' % (x, ops.getStress(), ops.getTangent()))
