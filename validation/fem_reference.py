#!/usr/bin/env python3
"""Independent static linear-elastic FEM reference solutions for tissuesim (scikit-fem).

Scenes (see validation/README.md):
  cantilever  box beam 0.1 x 0.02 x 0.02 m, clamped at x = 0, E = 5e4 Pa, nu = 0.3, rho = 1000 kg/m^3,
              gravity 9.81 m/s^2 along -y; P1 and P2 tets on a structured tet mesh, Euler-Bernoulli tip.
  cantilever-nu045  the same beam at nu = 0.45 (reference/cantilever_nu045*).
  liver4k     data/meshes/liver_4k (TetGen) in mesh units, E = 3000, nu in {0.3, 0.45}, rho = 1,
              gravity 0.981 along -y, every node with y >= ymax - 0.1 (ymax - ymin) fixed; P1 and P2.
  liver1k6, liver10k  the same sag scene on data/meshes/liver_1k6 and liver_10k.
  kidney_gmsh, liver_gmsh  the same sag scene on the gmsh meshes of validation/gmsh_organs.py (data/meshes).
  organ       the same sag scene on the project's own organ, tissuesim::mesh::organ_with_cell(cell) x 30
              (mesh units) at cell = 0.0133, 0.0095 (the default organ) and 0.0068 m; the meshes are
              exported by `cargo run --release --example organ_check -- export DIR CELL` (run by this
              script into build/organ/cXXXX/ when missing; the JSON records their SHA-256).

Outputs go to validation/reference/: node-wise CSV `node,ux,uy,uz` (mesh's own node order) and one JSON
summary per scene. Every solve is checked: the total reaction at the fixed dofs must balance the total
weight, and the P2 cantilever must agree with beam theory. The checks are printed and stored in the JSON.

Usage:  build/venv-validation/bin/python validation/fem_reference.py
            [--scene cantilever|cantilever-nu045|liver|liver1k6|liver10k|organ|kidney_gmsh|liver_gmsh|all]
            [--mesh-dir data/meshes] [--solver direct|amg] [--organ-dir build/organ]
(--mesh-dir defaults to $TISSUESIM_MESHES when set, else the repository's data/meshes.)
"""
import argparse
import hashlib
import json
import os
import platform
import resource
import subprocess
import sys
import time

import numpy as np
import pyamg
import scipy
import scipy.sparse.linalg as spla
import skfem
from skfem import (Basis, ElementTetP1, ElementTetP2, ElementVector, FacetBasis, Functional, LinearForm,
                   MeshTet, asm, condense)
from skfem.models.elasticity import lame_parameters, linear_elasticity

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
OUT = os.path.join(HERE, 'reference')
# The test meshes: $TISSUESIM_MESHES when set, else the repository's data/meshes.
MESH_DIR = os.environ.get('TISSUESIM_MESHES') or os.path.join(REPO, 'data', 'meshes')


# ----------------------------------------------------------------------------------------------------------
# I/O
# ----------------------------------------------------------------------------------------------------------

def _data_lines(path):
    """Non-empty lines of a TetGen file with '#' comments stripped."""
    with open(path) as fh:
        for line in fh:
            line = line.split('#', 1)[0].strip()
            if line:
                yield line


def read_tetgen(base):
    """Read TetGen `base.node` / `base.ele`. Returns (p (N,3) float, t (M,4) int, 0-based into p, ids (N,))."""
    lines = list(_data_lines(base + '.node'))
    n, dim = (int(v) for v in lines[0].split()[:2])
    assert dim == 3, 'only 3-D .node files'
    rows = np.array([[float(v) for v in l.split()[:4]] for l in lines[1:1 + n]])
    ids = rows[:, 0].astype(np.int64)
    p = rows[:, 1:4]
    lines = list(_data_lines(base + '.ele'))
    m, npt = (int(v) for v in lines[0].split()[:2])
    assert npt == 4, 'only linear (4-node) tets in the .ele file'
    t_ids = np.array([[int(v) for v in l.split()[1:5]] for l in lines[1:1 + m]], dtype=np.int64)
    # map node ids (0- or 1-based, possibly non-contiguous) to row indices
    lookup = {int(i): k for k, i in enumerate(ids)}
    t = np.vectorize(lookup.__getitem__)(t_ids)
    assert len(p) == n and len(t) == m
    return p, t, ids


def write_csv(path, ids, u, fmt='%.10e'):
    """Write `node,ux,uy,uz`; ids are the mesh's own node numbers, rows in the mesh's node order. `fmt` is the
    number format (validation/mixed_reference.py writes '%.7g' to keep the committed files small)."""
    line = '%d,' + ','.join([fmt] * 3) + '\n'
    with open(path, 'w') as fh:
        fh.write('node,ux,uy,uz\n')
        for i, (ux, uy, uz) in zip(ids, u):
            fh.write(line % (i, ux, uy, uz))


def write_json(path, obj):
    with open(path, 'w') as fh:
        json.dump(obj, fh, indent=2, sort_keys=False)
        fh.write('\n')


def relative_l2(a, b):
    """||a - b|| / ||b|| over all nodes and components (Frobenius norm of the (N,3) arrays)."""
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


# ----------------------------------------------------------------------------------------------------------
# FEM
# ----------------------------------------------------------------------------------------------------------

def tet_volumes(p, t):
    a, b, c = (p[t[:, k]] - p[t[:, 0]] for k in (1, 2, 3))
    return np.einsum('ij,ij->i', np.cross(a, b), c) / 6.0


MIDEDGE_RULE = 'geometric'  # or 'both-ends' (--midedge-rule): how P2 mid-edge nodes inherit the fixed set
SOLVER = 'direct'  # or 'amg' (--solver): SuperLU, or AMG-preconditioned CG to relative residual AMG_TOL
AMG_TOL = 1e-10
DIRECT_SOLVER = 'scipy.sparse.linalg.spsolve (SuperLU, COLAMD ordering)'


def rigid_modes(x, comp):
    """Six rigid-body modes for the dofs at locations x (3, n) with component comp (n,) (AMG near-null space)."""
    B = np.zeros((len(comp), 6))
    for c in range(3):
        B[comp == c, c] = 1.0
    for k, (a, b) in enumerate([(0, 1), (1, 2), (2, 0)]):  # rotation in the (a, b) plane
        B[comp == a, 3 + k] = -x[b, comp == a]
        B[comp == b, 3 + k] = x[a, comp == b]
    return B


DIRECT_ORDERING = 'colamd'  # or 'symmetric-mmd' (validation/mixed_reference.py): see lu_solve_symmetric
SYMMETRIC_SOLVER = ('SuperLU in symmetric mode (METIS nested-dissection ordering of A^T + A through pymetis, MMD '
                    'without it; diagonal pivots, diag_pivot_thresh 0), '
                    'up to 3 steps of iterative refinement (while the relative residual is >= 1e-10), falling '
                    'back to COLAMD with partial pivoting if it is still above 1e-9 and the normwise backward error '
                    'above 1e-14')


def pymetis_version():
    from importlib.metadata import version
    return version('pymetis')


def nested_dissection(A):
    """METIS nested-dissection fill-reducing ordering of the graph of A + A^T (pymetis), or None without pymetis.
    On 3-D P2 / Taylor-Hood matrices it roughly halves SuperLU's time and fill against MMD."""
    try:
        import pymetis
    except ImportError:
        return None
    G = (A + A.T).tocsr()
    G.setdiag(0)
    G.eliminate_zeros()
    G.sort_indices()
    perm, _ = pymetis.nested_dissection(adjacency=pymetis.CSRAdjacency(G.indptr, G.indices))
    perm = np.asarray(perm, dtype=np.int64)
    assert np.array_equal(np.sort(perm), np.arange(A.shape[0]))
    return perm


def lu_solve_symmetric(A, b):
    """SuperLU for a symmetric matrix, SPD or quasi-definite ([[A, B^T], [B, -C]] with A, C SPD): a symmetric
    fill-reducing ordering (METIS nested dissection when pymetis is there, else MMD on A^T + A) and diagonal pivots,
    which keeps the symmetric fill (TH system of liver_1k6 with MMD: 6x faster, 3x less fill than COLAMD with
    partial pivoting; of the organ c0068: nested dissection 75 s, MMD more than 16 min). Up to 3 steps of iterative refinement with the same factors,
    then COLAMD + partial pivoting if the residual is still not below 1e-9. Returns (x, description)."""
    perm = nested_dissection(A)
    if perm is not None:
        ordering = 'METIS nested dissection (pymetis %s)' % pymetis_version()
        lu = spla.splu(A[perm][:, perm].tocsc(), permc_spec='NATURAL', diag_pivot_thresh=0.0,
                       options=dict(SymmetricMode=True))
    else:
        ordering = 'MMD on A^T + A'
        perm = np.arange(A.shape[0])
        lu = spla.splu(A, permc_spec='MMD_AT_PLUS_A', diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))

    def lu_solve(r):  # solve with the factors of the permuted matrix (no reference cycle: freed on return)
        y = np.empty_like(r)
        y[perm] = lu.solve(r[perm])
        return y
    x = lu_solve(b)
    nb = np.linalg.norm(b)
    res = np.linalg.norm(A @ x - b) / nb
    steps = 0
    while res >= 1e-10 and steps < 3:  # iterative refinement with the same factors (nearly incompressible P2)
        x += lu_solve(b - A @ x)
        res = np.linalg.norm(A @ x - b) / nb
        steps += 1
    nnz = lu.nnz
    del lu, lu_solve
    # Displacement-only P2 at nu 0.499 stalls near 1e-9 after refinement (COLAMD with partial pivoting gets no
    # better: 7.8e-10 on the organ c0095, 1.6e-9 on c0068), so accept 1e-9 (the checks ask for 1e-8), or a
    # normwise backward error ||r|| / (||A||_inf ||x||_inf) below 1e-14 (the solve is then backward stable).
    backward = np.abs(A @ x - b).max() / (abs(A).sum(axis=1).max() * np.abs(x).max())
    if res < 1e-9 or backward < 1e-14:
        return x, SYMMETRIC_SOLVER + (': symmetric mode used, ordering %s (nnz(L+U) %d, %d refinement steps, '
                                      'relative residual %.1e, backward error %.1e)'
                                      % (ordering, nnz, steps, res, backward))
    x = spla.spsolve(A, b, permc_spec='COLAMD')
    return x, SYMMETRIC_SOLVER + ': residual %.1e in symmetric mode after %d refinement steps, COLAMD used' % (
        res, steps)


def dof_components(basis, order):
    """dof -> component (0, 1, 2) map of a vector P1/P2 basis (ElementVector interleaves components per node)."""
    comp = np.full(basis.N, -1, dtype=np.int64)
    for c in range(3):
        comp[basis.nodal_dofs[c]] = c
        if order == 2:
            comp[basis.edge_dofs[c]] = c
    assert (comp >= 0).all()
    return comp


def fixed_dofs(basis, mesh, order, fixed_vertex, fixed_point):
    """The fixed dofs (all components) of a vector P1/P2 basis: the vertices of the mask `fixed_vertex` and, for
    P2, the mid-edge nodes chosen by MIDEDGE_RULE (see solve_static)."""
    D = [basis.nodal_dofs[:, fixed_vertex].ravel()]
    if order == 2:
        e = mesh.edges  # (2, nedges) vertex indices
        fixed_edge = fixed_vertex[e[0]] & fixed_vertex[e[1]]
        if MIDEDGE_RULE == 'geometric':
            fixed_edge = fixed_point(0.5 * (mesh.p[:, e[0]] + mesh.p[:, e[1]]))
        D.append(basis.edge_dofs[:, fixed_edge].ravel())
    return np.unique(np.concatenate(D))


def solve_static(mesh, order, E, nu, rho, g, fixed_vertex, fixed_point=None, solver=None):
    """Static linear elasticity, body force (0, -rho g, 0), zero displacement on the fixed set.

    The fixed set is given on the vertices (boolean mask `fixed_vertex`) and as a predicate on points
    (`fixed_point(x)`, x of shape (3, n)). For P2 the mid-edge nodes are fixed
      - MIDEDGE_RULE == 'geometric' (default): iff the predicate holds at the mid-edge point, i.e. the rule
        "every node with y >= ..." applied to every P2 node; this is the discretisation of the continuum
        problem "the region y >= thr is clamped", to which uniformly refined P1 meshes also converge;
      - MIDEDGE_RULE == 'both-ends': iff both end vertices of the edge are fixed (the region clamped is then
        the union of the mesh entities spanned by fixed vertices, a mesh-dependent boundary).
    On the liver the two P2 variants differ by ~10% (relative L2); see validation/README.md.
    solver: 'direct' (SuperLU) or 'amg' (CG preconditioned by smoothed-aggregation AMG with the rigid-body
    near-null space, stopped at ||r|| < AMG_TOL ||b||); default the module's SOLVER (--solver).

    Returns dict with the basis, the full dof vector, the vertex displacements (Nv,3), checks and timing.
    """
    elem = ElementVector(ElementTetP2() if order == 2 else ElementTetP1())
    basis = Basis(mesh, elem)  # default quadrature: exact for the P2 stiffness and the P2 load
    lam, mu = lame_parameters(E, nu)

    t0 = time.perf_counter()
    K = asm(linear_elasticity(lam, mu), basis)

    @LinearForm
    def gravity(v, w):
        # f . v with f = (0, -rho g, 0): gravity points along -y
        return -rho * g * v[1]

    f = asm(gravity, basis)
    t_asm = time.perf_counter() - t0

    ndof = basis.N
    comp = dof_components(basis, order)
    D = fixed_dofs(basis, mesh, order, fixed_vertex, fixed_point)

    solver = solver or SOLVER
    t0 = time.perf_counter()
    A, b, _, I = condense(K, f, D=D)
    if solver == 'amg':
        A = A.tocsr()
        ml = pyamg.smoothed_aggregation_solver(A, B=rigid_modes(basis.doflocs[:, I], comp[I]),
                                               symmetry='symmetric', max_coarse=1000)
        res = []
        uI = ml.solve(b, tol=AMG_TOL, accel='cg', maxiter=5000, residuals=res)
        solver_desc = ('pyamg %s smoothed-aggregation AMG-preconditioned CG (rigid-body near-null space), '
                       'stop at ||r|| < %g ||b||: %d iterations' % (pyamg.__version__, AMG_TOL, len(res) - 1))
    else:
        A = A.tocsc()
        if DIRECT_ORDERING == 'symmetric-mmd':
            uI, solver_desc = lu_solve_symmetric(A, b)
        else:
            # SuperLU direct solve (COLAMD ordering: ~1 min for 77k P2 dofs on 2 cores, faster than MMD here)
            uI = spla.spsolve(A, b, permc_spec='COLAMD')
            solver_desc = DIRECT_SOLVER
    t_solve = time.perf_counter() - t0
    u = np.zeros(ndof)
    u[I] = uI

    # ---- checks -------------------------------------------------------------------------------------
    res_free = float(np.linalg.norm(A @ uI - b) / np.linalg.norm(b))
    r = K @ u - f  # reaction forces (nonzero only at fixed dofs)
    reaction = np.array([r[D][comp[D] == c].sum() for c in range(3)])
    load = np.array([f[comp == c].sum() for c in range(3)])
    vol = float(asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), basis))
    weight = rho * g * vol
    uv = u[basis.nodal_dofs].T.copy()  # (Nv, 3) displacement at the mesh vertices
    return dict(basis=basis, u=u, uv=uv, ndof=int(ndof), nfixed_dofs=int(len(D)),
                volume=vol, weight=weight, load=load, reaction=reaction, rel_residual=res_free,
                t_assemble=t_asm, t_solve=t_solve, solver=solver_desc,
                peak_rss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)


def report_checks(tag, s):
    """Print and return the equilibrium checks of one solve."""
    ry = s['reaction'][1]
    eq_err = abs(ry - s['weight']) / s['weight']
    load_err = abs(-s['load'][1] - s['weight']) / s['weight']
    print('  [%s] dofs %d (fixed %d), assemble %.1f s, solve %.1f s, rel. residual %.1e, process peak RSS '
          '%.0f MB; %s' % (tag, s['ndof'], s['nfixed_dofs'], s['t_assemble'], s['t_solve'], s['rel_residual'],
                            s['peak_rss_mb'], s['solver']))
    print('  [%s] total weight rho g V = %.6e, assembled load sum_y = %.6e, reaction (x,y,z) = '
          '(%.2e, %.6e, %.2e), |reaction_y - weight|/weight = %.1e'
          % (tag, s['weight'], s['load'][1], *s['reaction'], eq_err))
    ok = eq_err < 1e-8 and load_err < 1e-10 and s['rel_residual'] < 1e-8 \
        and abs(s['reaction'][0]) < 1e-8 * s['weight'] and abs(s['reaction'][2]) < 1e-8 * s['weight']
    print('  [%s] equilibrium check: %s' % (tag, 'PASS' if ok else 'FAIL'))
    return dict(volume=s['volume'], weight=s['weight'], load_sum=s['load'].tolist(),
                reaction_sum=s['reaction'].tolist(), reaction_vs_weight_rel_err=eq_err,
                linear_solve_rel_residual=s['rel_residual'], dofs=s['ndof'], fixed_dofs=s['nfixed_dofs'],
                assemble_s=round(s['t_assemble'], 2), solve_s=round(s['t_solve'], 2), solver=s['solver'],
                process_peak_rss_mb=round(s['peak_rss_mb']), passed=bool(ok))


def env_info():
    return dict(python=platform.python_version(), numpy=np.__version__, scipy=scipy.__version__,
                scikit_fem=skfem.__version__, p2_midedge_rule=MIDEDGE_RULE,
                solver=(DIRECT_SOLVER if DIRECT_ORDERING == 'colamd' else SYMMETRIC_SOLVER) if SOLVER == 'direct' else
                'pyamg %s AMG-preconditioned CG, relative tolerance %g' % (pyamg.__version__, AMG_TOL))


def sha256(path):
    with open(path, 'rb') as fh:
        return hashlib.sha256(fh.read()).hexdigest()


# ----------------------------------------------------------------------------------------------------------
# Scene a: cantilever
# ----------------------------------------------------------------------------------------------------------

CANT = dict(L=0.1, a=0.02, E=5e4, nu=0.3, rho=1000.0, g=9.81)
LATTICE_CELLS = (20, 4, 4)


def box_mesh(cells):
    L, a = CANT['L'], CANT['a']
    nx, ny, nz = cells
    return MeshTet.init_tensor(np.linspace(0, L, nx + 1), np.linspace(-a / 2, a / 2, ny + 1),
                               np.linspace(-a / 2, a / 2, nz + 1))


def tip_mean_uy(s, mesh):
    """Area average of u_y over the free end face x = L (exact integral of the FE field)."""
    L = CANT['L']
    basis = s['basis']
    facets = mesh.facets_satisfying(lambda x: np.isclose(x[0], L))
    fb = FacetBasis(mesh, basis.elem, facets=facets)
    uy = asm(Functional(lambda w: w['u'][1]), fb, u=fb.interpolate(s['u']))
    area = asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), fb)
    return float(uy / area)


def lattice_points(cells):
    """Lattice nodes, x fastest, then y, then z: index i + (nx+1)*(j + (ny+1)*k)."""
    L, a = CANT['L'], CANT['a']
    nx, ny, nz = cells
    k, j, i = np.meshgrid(np.arange(nz + 1), np.arange(ny + 1), np.arange(nx + 1), indexing='ij')
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    pts = np.stack([i * L / nx, -a / 2 + j * a / ny, -a / 2 + k * a / nz], axis=1)
    assert (i + (nx + 1) * (j + (ny + 1) * k) == np.arange(len(i))).all()
    return pts


def values_at_vertices(mesh, uv, pts):
    """Pick vertex values at points that are mesh vertices (match on a fine integer grid)."""
    h = 1e-9
    key = {tuple(np.rint(q / h).astype(np.int64)): n for n, q in enumerate(mesh.p.T)}
    idx = np.array([key[tuple(np.rint(q / h).astype(np.int64))] for q in pts])
    return uv[idx]


def run_cantilever(nu=CANT['nu']):
    """The cantilever at Poisson ratio nu; files cantilever*.{csv,json} at the default nu = 0.3, else
    cantilever_nuXXX*."""
    prefix = 'cantilever' if nu == CANT['nu'] else 'cantilever_nu%03d' % round(nu * 100)
    print('== %s: box %.2f x %.2f x %.2f m, E=%g, nu=%g, rho=%g, g=%g along -y, clamped at x=0'
          % (prefix, CANT['L'], CANT['a'], CANT['a'], CANT['E'], nu, CANT['rho'], CANT['g']))
    L, a, E, rho, g = (CANT[k] for k in ('L', 'a', 'E', 'rho', 'g'))
    A, I = a * a, a ** 4 / 12
    q = rho * g * A
    w_eb = q * L ** 4 / (8 * E * I)
    G = E / (2 * (1 + nu))
    kappa = 10 * (1 + nu) / (12 + 11 * nu)  # Cowper's shear coefficient, square section
    w_timo = w_eb + q * L ** 2 / (2 * kappa * G * A)
    print('  Euler-Bernoulli tip deflection q L^4/(8 E I) = %.6e m (downwards); Timoshenko (Cowper kappa=%.3f) '
          '= %.6e m' % (w_eb, kappa, w_timo))

    results, checks = {}, {}
    lattice = lattice_points(LATTICE_CELLS)
    lattice_ids = np.arange(len(lattice))
    for cells in [LATTICE_CELLS, (40, 8, 8)]:
        mesh = box_mesh(cells)
        fixed = np.isclose(mesh.p[0], 0.0)
        for order in (1, 2):
            tag = 'P%d %dx%dx%d' % (order, *cells)
            s = solve_static(mesh, order, E, nu, rho, g, fixed, fixed_point=lambda x: np.isclose(x[0], 0.0))
            checks[tag] = report_checks(tag, s)
            tip = tip_mean_uy(s, mesh)
            results[tag] = dict(cells=list(cells), order=order, tets=int(mesh.t.shape[1]),
                                vertices=int(mesh.p.shape[1]), dofs=s['ndof'], tip_mean_uy=tip,
                                tip_over_euler_bernoulli=-tip / w_eb, tip_over_timoshenko=-tip / w_timo,
                                max_abs_u=float(np.linalg.norm(s['uv'], axis=1).max()))
            print('  [%s] tip mean u_y = %.6e m  (%.4f x Euler-Bernoulli, %.4f x Timoshenko)'
                  % (tag, tip, -tip / w_eb, -tip / w_timo))
            ul = values_at_vertices(mesh, s['uv'], lattice)
            results[tag]['_lattice_u'] = ul

    ref = results['P2 40x8x8']
    p2 = results['P2 20x4x4']
    p1 = results['P1 20x4x4']
    conv = abs(p2['tip_mean_uy'] - ref['tip_mean_uy']) / abs(ref['tip_mean_uy'])
    lat_p2_vs_ref = relative_l2(p2['_lattice_u'], ref['_lattice_u'])
    lat_p1_vs_ref = relative_l2(p1['_lattice_u'], ref['_lattice_u'])
    print('  P2 20x4x4 vs P2 40x8x8: tip %.2e relative, lattice-node L2 %.2e' % (conv, lat_p2_vs_ref))
    print('  P1 20x4x4 vs P2 40x8x8: lattice-node L2 %.4f' % lat_p1_vs_ref)

    # sanity checks on the FEM itself
    if nu == CANT['nu']:
        sane_beam = abs(ref['tip_over_timoshenko'] - 1) < 0.03 and 1.0 < ref['tip_over_euler_bernoulli'] < 1.10
        beam_rule = 'P2 within 3% of Timoshenko and 0-10% above Euler-Bernoulli'
    else:
        # The fully clamped 3-D root (no Poisson contraction at x = 0) stiffens the beam more as nu grows: at
        # nu = 0.45 the 3-D P2 tip sits at Euler-Bernoulli, ~4% below Timoshenko (see validation/README.md), so
        # the nu = 0.3 rule does not apply; require the tip to lie between the two beam theories, 2% slack.
        sane_beam = ref['tip_over_euler_bernoulli'] > 0.98 and ref['tip_over_timoshenko'] < 1.02
        beam_rule = 'P2 between 0.98 x Euler-Bernoulli and 1.02 x Timoshenko'
    sane_conv = conv < 0.01
    sane_eq = all(c['passed'] for c in checks.values())
    print('  sanity: %s (L/h = 5, shear adds %.1f%%): %s'
          % (beam_rule, 100 * (w_timo / w_eb - 1),
             'PASS' if sane_beam else 'FAIL'))
    print('  sanity: P2 mesh-converged (tip change < 1%% from 20x4x4 to 40x8x8): %s'
          % ('PASS' if sane_conv else 'FAIL'))
    print('  sanity: reaction = weight on every solve: %s' % ('PASS' if sane_eq else 'FAIL'))

    os.makedirs(OUT, exist_ok=True)
    write_csv(os.path.join(OUT, '%s_p2_lattice.csv' % prefix), lattice_ids, ref['_lattice_u'])
    write_csv(os.path.join(OUT, '%s_p1_lattice.csv' % prefix), lattice_ids, p1['_lattice_u'])
    for r in results.values():
        del r['_lattice_u']
    summary = dict(
        scene=prefix,
        description='static linear elasticity, box beam along +x clamped at x=0 (all three components of every '
                    'node on x=0), gravity along -y; tip = area average of u_y over the free end face x=L',
        parameters=dict(L=L, cross_section=[a, a], E=E, nu=nu, rho=rho, g=g, gravity_direction=[0, -1, 0],
                        units='SI (m, Pa, kg/m^3, m/s^2)'),
        tip_deflection=dict(
            p1=p1['tip_mean_uy'], p2=ref['tip_mean_uy'], analytic_euler_bernoulli=-w_eb,
            analytic_timoshenko=-w_timo,
            note='p1 = P1 on the 20x4x4 lattice mesh (6 tets per cell), p2 = P2 on the 40x8x8 refinement '
                 '(P2 on 20x4x4 is within %.2e of it); signed u_y in metres, negative = downwards' % conv,
            p2_extrapolated_h2=ref['tip_mean_uy'] + (ref['tip_mean_uy'] - p2['tip_mean_uy']) / 3,
            p2_extrapolated_h2_note='Richardson extrapolation of the P2 20x4x4 and 40x8x8 tips assuming O(h^2)'),
        solutions=results,
        lattice=dict(cells=list(LATTICE_CELLS), box=[[0, L], [-a / 2, a / 2], [-a / 2, a / 2]],
                     node_order='i + (nx+1)*(j + (ny+1)*k), x fastest',
                     p2_csv='%s_p2_lattice.csv (P2 on 40x8x8; lattice points are mesh vertices)' % prefix,
                     p1_csv='%s_p1_lattice.csv (P1 on the 20x4x4 lattice itself)' % prefix,
                     p2_20x4x4_vs_p2_csv_rel_l2=lat_p2_vs_ref, p1_csv_vs_p2_csv_rel_l2=lat_p1_vs_ref),
        checks=dict(equilibrium=checks, p2_vs_beam_theory_passed=bool(sane_beam), p2_vs_beam_theory_rule=beam_rule,
                    p2_mesh_convergence_passed=bool(sane_conv)),
        environment=env_info())
    write_json(os.path.join(OUT, '%s.json' % prefix), summary)
    return sane_beam and sane_conv and sane_eq


# ----------------------------------------------------------------------------------------------------------
# Sag scenes: liver_4k (b, c), liver_1k6, liver_10k, the project's organ at three resolutions
# ----------------------------------------------------------------------------------------------------------

LIVER = dict(E=3000.0, rho=1.0, g=0.981, fixed_fraction=0.1)


def sag_mesh(base, name):
    """Read the TetGen mesh `base`.node/.ele for the sag scene: dict of p, t, ids, vol (per tet), mesh (MeshTet,
    vertex order kept), ymin, ymax, ythr (fixing threshold), fixed (vertex mask y >= ythr)."""
    p, t, ids = read_tetgen(base)
    vol = tet_volumes(p, t)
    print('== %s: %d nodes, %d tets, volume %.4f, all tets positive: %s'
          % (name, len(p), len(t), vol.sum(), bool((vol > 0).all())))
    mesh = MeshTet(p.T.copy(), t.T.copy())
    assert np.array_equal(mesh.p.T, p), 'skfem must keep the vertex order'
    ymin, ymax = p[:, 1].min(), p[:, 1].max()
    ythr = ymax - LIVER['fixed_fraction'] * (ymax - ymin)
    fixed = p[:, 1] >= ythr
    return dict(p=p, t=t, ids=ids, vol=vol, mesh=mesh, ymin=ymin, ymax=ymax, ythr=ythr, fixed=fixed)


def run_sag(prefix, name, base, mesh_file, nus=(0.3, 0.45), mesh_extra=None, csv_fmt='%.10e'):
    """Gravity sag (LIVER parameters) of the TetGen mesh `base`.node/.ele, P2 and P1 at each nu; writes
    {prefix}_nuXXX_p2.csv, {prefix}_nuXXX_p1.csv and {prefix}_nuXXX.json to OUT. `name` is the mesh's name in
    messages and the description, `mesh_file` its provenance in the JSON, `mesh_extra` more JSON mesh data."""
    m = sag_mesh(base, name)
    p, t, ids, vol, mesh, ymin, ymax, ythr, fixed = (m[k] for k in ('p', 't', 'ids', 'vol', 'mesh', 'ymin', 'ymax',
                                                                    'ythr', 'fixed'))
    nfixed_edges = int((fixed[mesh.edges[0]] & fixed[mesh.edges[1]]).sum())
    print('  y range [%.4f, %.4f], fixed: y >= %.4f -> %d nodes; %d edges (P2 mid-edge nodes fixed with '
          'them under --midedge-rule both-ends); P2 nodes: %d, mid-edge rule %s' % (ymin, ymax, ythr, fixed.sum(), nfixed_edges, len(p) + mesh.edges.shape[1], MIDEDGE_RULE))
    # how close the nearest vertex / mid-edge point lies to the threshold (a tiny margin would make the fixed
    # set depend on rounding in whoever else applies the rule)
    ymid = 0.5 * (p[mesh.edges[0], 1] + p[mesh.edges[1], 1])
    margin = dict(vertices=float(np.abs(p[:, 1] - ythr).min()), midedge=float(np.abs(ymid - ythr).min()))
    print('  smallest |y - threshold|: vertices %.3e, mid-edge points %.3e' % (margin['vertices'],
                                                                               margin['midedge']))
    ok = True
    for nu in nus:
        tag = 'nu%03d' % round(nu * 100)
        print('-- %s %s: E=%g, nu=%g, rho=%g, g=%g along -y' % (name, tag, LIVER['E'], nu, LIVER['rho'],
                                                               LIVER['g']))
        sol, checks = {}, {}
        for order in (2, 1):
            s = solve_static(mesh, order, LIVER['E'], nu, LIVER['rho'], LIVER['g'], fixed,
                             fixed_point=lambda x: x[1] >= ythr)
            checks['P%d' % order] = report_checks('P%d' % order, s)
            sol[order] = s['uv']
            write_csv(os.path.join(OUT, '%s_%s_p%d.csv' % (prefix, tag, order)), ids, s['uv'], csv_fmt)
        err = relative_l2(sol[1], sol[2])
        maxerr = float(np.linalg.norm(sol[1] - sol[2], axis=1).max())
        umax = {o: float(np.linalg.norm(sol[o], axis=1).max()) for o in (1, 2)}
        uymin = {o: float(sol[o][:, 1].min()) for o in (1, 2)}
        print('  max |u|: P2 %.6e, P1 %.6e; min u_y: P2 %.6e, P1 %.6e'
              % (umax[2], umax[1], uymin[2], uymin[1]))
        print('  P1 vs P2 relative L2 over vertices = %.4f (%.2f%%), max nodal |du| = %.4e (%.2f%% of max|u_P2|)'
              % (err, 100 * err, maxerr, 100 * maxerr / umax[2]))
        sane = all(c['passed'] for c in checks.values()) and np.all(sol[2][fixed] == 0) and uymin[2] < 0
        print('  sanity (equilibrium, fixed nodes at zero, sag downwards): %s' % ('PASS' if sane else 'FAIL'))
        ok = ok and sane
        mesh_json = dict(file=mesh_file, nodes=int(len(p)), tets=int(len(t)),
                         volume=float(vol.sum()), y_range=[float(ymin), float(ymax)], y_fixed_threshold=float(ythr),
                         fixed_nodes=int(fixed.sum()), p2_nodes=int(len(p) + mesh.edges.shape[1]),
                         y_threshold_margin=margin)
        mesh_json.update(mesh_extra or {})
        write_json(os.path.join(OUT, '%s_%s.json' % (prefix, tag)), dict(
            scene='%s_%s' % (prefix, tag),
            description='static linear elasticity, gravity sag of ' + name + ' in mesh units; every node with '
                        'y >= ymax - 0.1 (ymax - ymin) fixed in all three components; P2 = quadratic tets on '
                        'the same mesh (edge midpoints added; mid-edge node fixed per p2_midedge_rule: "both-ends" = iff '
                        'both edge ends are fixed, "geometric" = iff the midpoint satisfies the y rule); '
                        'displacements reported at the original vertices in file order',
            mesh=mesh_json,
            parameters=dict(E=LIVER['E'], nu=nu, rho=LIVER['rho'], g=LIVER['g'], gravity_direction=[0, -1, 0],
                            units='mesh units (consistent)'),
            files=dict(p2='%s_%s_p2.csv' % (prefix, tag), p1='%s_%s_p1.csv' % (prefix, tag)),
            p1_vs_p2_relative_l2=err, p1_vs_p2_max_nodal_error=maxerr,
            max_abs_u=dict(p2=umax[2], p1=umax[1]), min_uy=dict(p2=uymin[2], p1=uymin[1]),
            checks=dict(equilibrium=checks, passed=bool(sane)),
            environment=env_info()))
    return ok


def run_liver(mesh_dir, mesh='liver_4k', prefix='liver4k', nus=(0.3, 0.45), csv_fmt='%.10e'):
    """The liver sag scene on the TetGen liver `mesh` of mesh_dir (liver_4k: scenes b, c)."""
    extra = None
    if mesh.endswith('_gmsh'):
        base = os.path.join(mesh_dir, mesh)
        extra = dict(sha256={mesh + '.node': sha256(base + '.node'), mesh + '.ele': sha256(base + '.ele')},
                     mesher='gmsh (validation/gmsh_organs.py)')
    return run_sag(prefix, mesh, os.path.join(mesh_dir, mesh), '%s.node/.ele (data/meshes)' % mesh, nus, extra,
                   csv_fmt)


ORGAN_CELLS = (0.0133, 0.0095, 0.0068)  # lattice cell edge (m) of tissuesim::mesh::organ_with_cell
ORGAN_SCALE = 30.0  # examples/organ_check.rs scales the organ (m) by 30 to liver size in mesh units
ORGAN_DIR = os.path.join(REPO, 'build', 'organ')


def organ_mesh(cell, organ_dir):
    """TetGen base path of the organ of cell `cell` in organ_dir/cXXXX/, exported with cargo when missing."""
    d = os.path.join(organ_dir, 'c%04d' % round(cell * 1e4))
    base = os.path.join(d, 'organ')
    if not (os.path.exists(base + '.node') and os.path.exists(base + '.ele')):
        cmd = ['cargo', 'run', '--release', '--example', 'organ_check', '--', 'export', d, repr(cell)]
        print('  %s.node/.ele missing; running %s' % (base, ' '.join(cmd)))
        subprocess.run(cmd, cwd=REPO, check=True)
    return base


def run_organ(organ_dir, cells=ORGAN_CELLS, nus=(0.3, 0.45)):
    """The liver sag scene on tissuesim's own organ (organ_with_cell(cell) x 30) at each lattice cell."""
    ok = True
    for cell in cells:
        base = organ_mesh(cell, organ_dir)
        label = 'c%04d' % round(cell * 1e4)
        extra = dict(cell_m=cell, scale_to_mesh_units=ORGAN_SCALE,
                     generator='tissuesim::mesh::organ_with_cell(%r), nodes x %g, exported by `cargo run --release '
                               '--example organ_check -- export DIR %r` (default organ: cell 0.0095)'
                               % (cell, ORGAN_SCALE, cell),
                     sha256={'organ.node': sha256(base + '.node'), 'organ.ele': sha256(base + '.ele')})
        ok = run_sag('organ_%s' % label, 'the organ of cell %g m (x %g)' % (cell, ORGAN_SCALE), base,
                     'organ.node/.ele (examples/organ_check.rs export, cell %g)' % cell, nus, extra) and ok
    return ok


SCENES = ('cantilever', 'cantilever-nu045', 'liver', 'liver1k6', 'liver10k', 'organ', 'kidney_gmsh', 'liver_gmsh')


def main():
    global OUT, MIDEDGE_RULE, SOLVER
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', choices=list(SCENES) + ['all'], default='all',
                    help='liver = liver_4k (scenes b, c); all = every scene')
    ap.add_argument('--mesh-dir', default=MESH_DIR)
    ap.add_argument('--midedge-rule', choices=['geometric', 'both-ends'], default='geometric',
                    help='P2 mid-edge node fixed iff the mid-edge point itself satisfies the fixing rule '
                         '(default) or iff both edge ends are fixed (sensitivity study)')
    ap.add_argument('--solver', choices=['direct', 'amg'], default='direct',
                    help='SuperLU (default) or AMG-preconditioned CG to a relative residual of %g' % AMG_TOL)
    ap.add_argument('--organ-dir', default=ORGAN_DIR,
                    help='where the organ meshes are (cXXXX/organ.node/.ele), exported there when missing')
    ap.add_argument('--out', default=OUT, help='output directory (default validation/reference)')
    args = ap.parse_args()
    OUT, MIDEDGE_RULE, SOLVER = os.path.abspath(args.out), args.midedge_rule, args.solver
    os.makedirs(OUT, exist_ok=True)
    t0 = time.perf_counter()
    ok = True
    if args.scene in ('cantilever', 'all'):
        ok = run_cantilever() and ok
    if args.scene in ('cantilever-nu045', 'all'):
        ok = run_cantilever(nu=0.45) and ok
    if args.scene in ('liver', 'all'):
        ok = run_liver(args.mesh_dir) and ok
    if args.scene in ('liver1k6', 'all'):
        ok = run_liver(args.mesh_dir, 'liver_1k6', 'liver1k6') and ok
    if args.scene in ('liver10k', 'all'):
        ok = run_liver(args.mesh_dir, 'liver_10k', 'liver10k') and ok
    if args.scene in ('organ', 'all'):
        ok = run_organ(args.organ_dir) and ok
    for gm in ('kidney_gmsh', 'liver_gmsh'):  # meshes of validation/gmsh_organs.py
        if args.scene in (gm, 'all'):
            ok = run_liver(args.mesh_dir, gm, gm, csv_fmt='%.7g') and ok  # compact: newer files
    print('== all sanity checks %s (%.0f s)' % ('PASSED' if ok else 'FAILED', time.perf_counter() - t0))
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
