"""Peer timing: Bender's PositionBasedDynamics (PyPI package pypbd) on a TetGen liver mesh.

Scene: the mesh in its own units (the liver is ~6.5 units across), E = 3000, nu = 0.45, density 1 (the
parameters of SOFA's liver demo), dt = 1 ms, gravity -9.81 along y, particles in the top 3% of the y range fixed,
FEM-based PBD tet constraints (pypbd solid model 2), 5 solver iterations, one substep. With these settings pypbd
is stable on every shared liver mesh; its XPBD FEM (model 3), and model 2 in SI units with real tissue density,
were seen to blow up, so compare timings only against a stable run (volume_ratio near 1).

    python3 -m venv /tmp/peers && /tmp/peers/bin/pip install pypbd numpy
    /tmp/peers/bin/python validation/peers/pypbd_liver.py data/meshes/liver_4k [steps] [iterations] [solid_model]

Prints one line: nodes tets iterations ms_per_step volume_ratio
"""
import sys, time
import numpy as np
import pypbd as pbd

SCALE, E, NU, RHO, DT = 1.0, 3e3, 0.45, 1.0, 1e-3


def read_tetgen(base):
    lines = open(base + '.node').read().split('\n')
    n = int(lines[0].split()[0])
    p = np.array([list(map(float, l.split()[1:4])) for l in lines[1:1 + n]])
    lines = open(base + '.ele').read().split('\n')
    m = int(lines[0].split()[0])
    t = np.array([list(map(int, l.split()[1:5])) for l in lines[1:1 + m]])
    return p, t


def tet_volumes(p, t):
    a, b, c = (p[t[:, k]] - p[t[:, 0]] for k in (1, 2, 3))
    return np.einsum('ij,ij->i', np.cross(a, b), c) / 6


base = sys.argv[1]
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 200
iterations = int(sys.argv[3]) if len(sys.argv) > 3 else 5
p, t = read_tetgen(base)
p = p * SCALE
vol = tet_volumes(p, t)
mass = np.zeros(len(p))
for k in range(4):
    np.add.at(mass, t[:, k], RHO * vol / 4)

sim = pbd.Simulation.getCurrent()
sim.initDefault()
model = sim.getModel()
ts = sim.getTimeStep()
ts.setValueUInt(pbd.TimeStepController.NUM_SUB_STEPS, 1)
ts.setValueUInt(pbd.TimeStepController.MAX_ITERATIONS, iterations)
pbd.TimeManager.getCurrent().setTimeStepSize(DT)
tm = model.addTetModel([x for x in p], t.flatten().tolist())
pd = model.getParticles()
ymax, ymin = p[:, 1].max(), p[:, 1].min()
fixed = p[:, 1] > ymax - 0.03 * (ymax - ymin)
for i in range(len(p)):
    pd.setMass(i, 0.0 if fixed[i] else float(mass[i]))
MODEL = int(sys.argv[4]) if len(sys.argv) > 4 else 2
model.addSolidConstraints(tm, MODEL, E if MODEL in (2, 3, 6) else 1.0, NU, 1.0, False, False)

ts.step(model)  # warm-up
t0 = time.perf_counter()
for _ in range(steps):
    ts.step(model)
ms = (time.perf_counter() - t0) / steps * 1e3
q = np.array([pd.getPosition(i) for i in range(len(p))]).reshape(-1, 3)
print(len(p), len(t), iterations, '%.3f' % ms, '%.4f' % (tet_volumes(q, t).sum() / vol.sum()))
