#!/usr/bin/env python3
"""Mesh-convergence check of the liver_4k sag references (how far is P1 from P2, and is P2 converged?).

Solves the liver_4k sag scene (same loads and fixing rule as fem_reference.py) with P1 on the liver_4k mesh
uniformly refined once (h/2, 8 tets per tet) and twice (h/4), and compares the displacement at the original
4,152 vertices with the committed P2 reference (validation/reference/liver4k_nuXXX_p2.csv). Refined vertices
take their "fixed" flag from the same rule, y >= ymax - 0.1 (ymax - ymin). h/4 (about 1.06 M tets) is solved
with CG preconditioned by smoothed-aggregation AMG (pyamg, rigid-body near-null space), the others directly.

    build/venv-validation/bin/python validation/convergence_liver.py [--nu 0.3] [--levels 2]

Writes validation/reference/liver4k_nuXXX_convergence.json.
"""
import argparse
import json
import os
import sys
import time

import numpy as np
import pyamg
import scipy.sparse.linalg as spla
from skfem import Basis, ElementTetP1, ElementVector, LinearForm, MeshTet, asm, condense
from skfem.models.elasticity import lame_parameters, linear_elasticity

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fem_reference as fr  # noqa: E402
from compare import read_csv  # noqa: E402


def rigid_modes(x, comp):
    """Six rigid-body modes for the dofs at locations x (3, n) with component comp (n,)."""
    B = np.zeros((len(comp), 6))
    for c in range(3):
        B[comp == c, c] = 1.0
    for k, (a, b) in enumerate([(0, 1), (1, 2), (2, 0)]):  # rotation in the (a, b) plane
        B[comp == a, 3 + k] = -x[b, comp == a]
        B[comp == b, 3 + k] = x[a, comp == b]
    return B


def solve_p1(mesh, E, nu, rho, g, fixed, amg):
    basis = Basis(mesh, ElementVector(ElementTetP1()))
    lam, mu = lame_parameters(E, nu)
    t0 = time.perf_counter()
    K = asm(linear_elasticity(lam, mu), basis)
    f = asm(LinearForm(lambda v, w: -rho * g * v[1]), basis)
    D = basis.nodal_dofs[:, fixed].ravel()
    A, b, _, I = condense(K, f, D=D)
    t1 = time.perf_counter()
    if amg:
        comp = np.zeros(basis.N, dtype=np.int64)
        for c in range(3):
            comp[basis.nodal_dofs[c]] = c
        ml = pyamg.smoothed_aggregation_solver(A.tocsr(), B=rigid_modes(basis.doflocs[:, I], comp[I]),
                                               symmetry='symmetric', max_coarse=1000)
        res = []
        uI = ml.solve(b, tol=1e-10, accel='cg', maxiter=2000, residuals=res)
        info = 'AMG-CG %d iterations' % (len(res) - 1)
    else:
        uI = spla.spsolve(A.tocsc(), b, permc_spec='COLAMD')
        info = 'SuperLU'
    rel = float(np.linalg.norm(A @ uI - b) / np.linalg.norm(b))
    u = np.zeros(basis.N)
    u[I] = uI
    return u[basis.nodal_dofs].T, dict(dofs=int(basis.N), tets=int(mesh.t.shape[1]), solver=info,
                                        rel_residual=rel, assemble_s=round(t1 - t0, 1),
                                        solve_s=round(time.perf_counter() - t1, 1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--nu', type=float, default=0.3)
    ap.add_argument('--levels', type=int, default=2, help='uniform refinements of P1 (1 or 2)')
    ap.add_argument('--mesh-dir', default=fr.MESH_DIR)
    args = ap.parse_args()
    tag = 'nu%03d' % round(args.nu * 100)
    p, t, ids = fr.read_tetgen(os.path.join(args.mesh_dir, 'liver_4k'))
    n0 = len(p)
    ids_ref, u2 = read_csv(os.path.join(fr.OUT, 'liver4k_%s_p2.csv' % tag))
    _, u1 = read_csv(os.path.join(fr.OUT, 'liver4k_%s_p1.csv' % tag))
    assert np.array_equal(ids_ref, ids)
    ymin, ymax = p[:, 1].min(), p[:, 1].max()
    ythr = ymax - fr.LIVER['fixed_fraction'] * (ymax - ymin)
    out = dict(scene='liver4k_%s' % tag, reference='liver4k_%s_p2.csv' % tag,
               levels={'P1 h': dict(rel_l2_vs_p2=fr.relative_l2(u1, u2),
                                    max_abs_u=float(np.linalg.norm(u1, axis=1).max()))})
    print('liver_4k %s: P2 max|u| %.6e; P1 h vs P2: rel L2 %.4f' % (tag, np.linalg.norm(u2, axis=1).max(),
                                                                   out['levels']['P1 h']['rel_l2_vs_p2']))
    mesh = MeshTet(p.T.copy(), t.T.copy())
    prev = u1
    for lev in range(1, args.levels + 1):
        mesh = mesh.refined()
        assert np.allclose(mesh.p[:, :n0].T, p), 'refinement must keep the original vertices first'
        fixed = mesh.p[1] >= ythr
        u, info = solve_p1(mesh, fr.LIVER['E'], args.nu, fr.LIVER['rho'], fr.LIVER['g'], fixed, amg=lev >= 2)
        u = u[:n0]
        name = 'P1 h/%d' % 2 ** lev
        info.update(rel_l2_vs_p2=fr.relative_l2(u, u2), rel_l2_vs_previous_level=fr.relative_l2(prev, u),
                    max_abs_u=float(np.linalg.norm(u, axis=1).max()))
        out['levels'][name] = info
        print('%s: %d tets, %d dofs, %s (asm %.0f s, solve %.0f s, residual %.1e): max|u| %.6e, rel L2 vs P2 '
              '%.4f' % (name, info['tets'], info['dofs'], info['solver'], info['assemble_s'], info['solve_s'],
                        info['rel_residual'], info['max_abs_u'], info['rel_l2_vs_p2']))
        prev = u
    with open(os.path.join(fr.OUT, 'liver4k_%s_convergence.json' % tag), 'w') as fh:
        json.dump(out, fh, indent=2)
        fh.write('\n')


if __name__ == '__main__':
    main()
