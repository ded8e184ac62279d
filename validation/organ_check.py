"""P1 and P2 static references for the default-organ diagnostic (docs/VALIDATION.md section 1.4).

    python validation/organ_check.py DIR      # reads DIR/organ.node/.ele, writes DIR/organ_p1.csv, organ_p2.csv
"""
import os
import sys

import numpy as np
from skfem import MeshTet

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fem_reference as fr  # noqa: E402

d = sys.argv[1]
p, t, ids = fr.read_tetgen(os.path.join(d, 'organ'))
mesh = MeshTet(p.T.copy(), t.T.copy())
ymin, ymax = p[:, 1].min(), p[:, 1].max()
thr = ymax - 0.1 * (ymax - ymin)
fixed = p[:, 1] >= thr
for order in (2, 1):
    s = fr.solve_static(mesh, order, 3000.0, 0.3, 1.0, 0.981, fixed, fixed_point=lambda x: x[1] >= thr)
    fr.write_csv(os.path.join(d, 'organ_p%d.csv' % order), ids, s['uv'])
    print('organ_check: P%d max|u| %.4e (%d nodes, %d fixed)'
          % (order, np.linalg.norm(s['uv'], axis=1).max(), len(p), fixed.sum()))
