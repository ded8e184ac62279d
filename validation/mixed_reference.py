#!/usr/bin/env python3
"""Taylor-Hood (P2 displacement, P1 pressure) references for the gravity-sag scene at nearly incompressible nu,
and the errors of displacement-only P1 and P2 against them (scikit-fem; validation/README.md section g).

A displacement-only P2 solution stiffens as nu -> 0.5 (volumetric locking); the mixed Taylor-Hood element is
inf-sup stable and does not lock. With p = lambda div u:

    int 2 mu eps(u):eps(v) + int p div v = int f.v        for all v (P2, zero on the fixed nodes)
    int q div u - int p q / lambda       = 0              for all q (P1)

i.e. the symmetric indefinite block system [[A, B^T], [B, -C]] [u; p] = [f; 0], condensed on the fixed
displacement dofs and solved with SuperLU (or MINRES with a block-diagonal preconditioner, --solver minres).

The scene is fem_reference.py's sag scene (mesh units, E = 3000, rho = 1, g = 0.981 along -y, every node with
y >= ymax - 0.1 (ymax - ymin) fixed in all components, geometric mid-edge rule for the P2 nodes). For each mesh
and nu it writes to validation/reference/:
    {prefix}_nuXXX_th.csv   Taylor-Hood displacement at the original vertices (node,ux,uy,uz, '%.7g')
    {prefix}_nuXXX_p1.csv   displacement-only P1 (not at nu 0.3, nor at 0.45 where fem_reference.py wrote the
                            P1 and P2 CSVs)
    {prefix}_th.json        per mesh: every nu's TH solve, the P1 and P2 errors against TH, the checks, timings
Displacement-only P2 at nu 0.49/0.499 is solved for the table but its CSV is written only with --p2-dir DIR.
At nu 0.3 and 0.45 the P1/P2 solutions are read from the committed fem_reference.py CSVs when present.

Checks (printed and stored): assembled load = -rho g V; reaction at the fixed dofs (A u + B^T p - f) balances
the weight; relative residual of the condensed system; with --check-nu030, TH at nu 0.3 against the committed
displacement-only P2 reference (they are two discretisations of the same compressible problem: ~1%).

Usage:  build/venv-validation/bin/python validation/mixed_reference.py --scene liver1k6 [--nu 0.45 0.49 0.499]
            [--check-nu030] [--solver direct|minres] [--out DIR] [--p2-dir DIR] [--mesh-dir data/meshes]
        scenes: liver1k6, liver4k, liver10k, organ (three cells; --organ-cell to pick one), kidney_gmsh,
                liver_gmsh (meshes made by validation/gmsh_organs.py) and their _coarse and _fine
                refinements, all
"""
import argparse
import os
import resource
import sys
import time

import numpy as np
import pyamg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTetP1, ElementTetP2, ElementVector, Functional, LinearForm, asm, condense
from skfem.helpers import ddot, div, sym_grad
from skfem.models.elasticity import lame_parameters

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fem_reference as fr  # noqa: E402  (shared I/O, sag-scene set-up, displacement-only solver, checks)
from compare import read_csv  # noqa: E402

CSV_FMT = '%.7g'
NUS = (0.45, 0.49, 0.499)
MINRES_TOL = 1e-10


def nu_tag(nu):
    """nu030, nu045, nu049, nu0499."""
    k = round(nu * 100)
    return 'nu%03d' % k if abs(k - nu * 100) < 1e-9 else 'nu%04d' % round(nu * 1000)


def rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def solve_mixed(mesh, E, nu, rho, g, fixed_vertex, fixed_point, solver='direct'):
    """Taylor-Hood P2/P1 static linear elasticity of the sag scene. Returns dict like fr.solve_static plus the
    pressure at the vertices."""
    ub = Basis(mesh, ElementVector(ElementTetP2()), intorder=4)
    pb = Basis(mesh, ElementTetP1(), intorder=4)
    lam, mu = lame_parameters(E, nu)

    @BilinearForm
    def a(u, v, w):
        return 2.0 * mu * ddot(sym_grad(u), sym_grad(v))

    @BilinearForm
    def b(u, q, w):
        return div(u) * q

    @BilinearForm
    def c(p, q, w):
        return p * q / lam

    @BilinearForm
    def mass(p, q, w):
        return p * q

    @LinearForm
    def gravity(v, w):
        return -rho * g * v[1]

    t0 = time.perf_counter()
    A = asm(a, ub).tocsr()
    B = asm(b, ub, pb).tocsr()  # (pressure dofs, displacement dofs): rows = test q, columns = trial u
    C = asm(c, pb).tocsr()
    f = asm(gravity, ub)
    nu_dof, np_dof = ub.N, pb.N
    assert B.shape == (np_dof, nu_dof)
    K = sp.bmat([[A, B.T], [B, -C]], format='csr')
    F = np.concatenate([f, np.zeros(np_dof)])
    t_asm = time.perf_counter() - t0

    comp = fr.dof_components(ub, 2)
    D = fr.fixed_dofs(ub, mesh, 2, fixed_vertex, fixed_point)  # displacement dofs come first in K
    t0 = time.perf_counter()
    Kc, Fc, _, I = condense(K, F, D=D)
    Kc = Kc.tocsc()
    if solver == 'direct':
        # the condensed matrix is quasi-definite (A_II and C SPD): SuperLU in symmetric mode
        xI, solver_desc = fr.lu_solve_symmetric(Kc, Fc)
    else:
        xI, solver_desc = minres_block(Kc, Fc, I, nu_dof, ub, comp, pb, mass, mu, lam)
    t_solve = time.perf_counter() - t0
    x = np.zeros(nu_dof + np_dof)
    x[I] = xI
    u, p = x[:nu_dof], x[nu_dof:]

    res = float(np.linalg.norm(Kc @ xI - Fc) / np.linalg.norm(Fc))
    r = A @ u + B.T @ p - f  # reactions (nonzero only at fixed dofs)
    free = np.setdiff1d(np.arange(nu_dof), D)
    momentum_res = float(np.linalg.norm(r[free]) / np.linalg.norm(f[free]))
    reaction = np.array([r[D][comp[D] == k].sum() for k in range(3)])
    load = np.array([f[comp == k].sum() for k in range(3)])
    vol = float(asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), pb))
    uv = u[ub.nodal_dofs].T.copy()
    return dict(u=u, p=p, uv=uv, ndof=int(nu_dof + np_dof), ndof_u=int(nu_dof), ndof_p=int(np_dof),
                nfixed_dofs=int(len(D)), volume=vol, weight=rho * g * vol, load=load, reaction=reaction,
                rel_residual=res, momentum_residual=momentum_res, t_assemble=t_asm, t_solve=t_solve,
                solver=solver_desc, peak_rss_mb=rss_mb(), lam=lam, mu=mu)


def minres_block(Kc, Fc, I, nu_dof, ub, comp, pb, mass, mu, lam):
    """MINRES on the condensed saddle-point system with the block-diagonal preconditioner
    diag(AMG(A_II), M_p / (1/(2 mu) + 1/lambda)) (pressure mass matrix, inverted by a sparse LU)."""
    Iu = I[I < nu_dof]
    nuI = len(Iu)
    A_II = Kc[:nuI, :nuI].tocsr()
    Mp = asm(mass, pb).tocsc()
    ml = pyamg.smoothed_aggregation_solver(A_II, B=fr.rigid_modes(ub.doflocs[:, Iu], comp[Iu]),
                                           symmetry='symmetric', max_coarse=1000)
    Pu = ml.aspreconditioner(cycle='V')
    s = 1.0 / (1.0 / (2.0 * mu) + 1.0 / lam)  # Schur complement ~ M_p / (1/(2mu) + 1/lambda)
    Mlu = spla.splu(Mp)

    def prec(r):
        return np.concatenate([Pu @ r[:nuI], s * Mlu.solve(r[nuI:])])

    M = spla.LinearOperator(Kc.shape, matvec=prec)
    it = [0]

    def cb(xk):
        it[0] += 1

    x, info = spla.minres(Kc, Fc, M=M, rtol=MINRES_TOL, maxiter=20000, callback=cb)
    desc = ('MINRES (scipy, rtol %g in the preconditioned norm), block-diagonal preconditioner: pyamg %s '
            'smoothed-aggregation AMG V-cycle on A, pressure mass matrix / (1/(2 mu) + 1/lambda) by sparse LU; '
            '%d iterations, info %d' % (MINRES_TOL, pyamg.__version__, it[0], info))
    return x, desc


def check_line(tag, s):
    ry = s['reaction'][1]
    eq_err = abs(ry - s['weight']) / s['weight']
    load_err = abs(-s['load'][1] - s['weight']) / s['weight']
    print('  [%s] dofs %d (u %d + p %d, fixed %d), assemble %.1f s, solve %.1f s, rel. residual %.1e, momentum '
          'residual %.1e, process peak RSS %.0f MB; %s'
          % (tag, s['ndof'], s['ndof_u'], s['ndof_p'], s['nfixed_dofs'], s['t_assemble'], s['t_solve'],
             s['rel_residual'], s['momentum_residual'], s['peak_rss_mb'], s['solver']))
    print('  [%s] weight %.6e, load sum_y %.6e, reaction (%.2e, %.6e, %.2e), |reaction_y - weight|/weight %.1e'
          % (tag, s['weight'], s['load'][1], *s['reaction'], eq_err))
    tol_res = 1e-8
    ok = (eq_err < 1e-7 and load_err < 1e-10 and s['rel_residual'] < tol_res
          and abs(s['reaction'][0]) < 1e-7 * s['weight'] and abs(s['reaction'][2]) < 1e-7 * s['weight'])
    print('  [%s] equilibrium/residual check: %s' % (tag, 'PASS' if ok else 'FAIL'))
    return dict(volume=s['volume'], weight=s['weight'], load_sum=s['load'].tolist(),
                reaction_sum=s['reaction'].tolist(), reaction_vs_weight_rel_err=eq_err,
                linear_solve_rel_residual=s['rel_residual'], momentum_rel_residual=s['momentum_residual'],
                dofs=s['ndof'], dofs_u=s['ndof_u'], dofs_p=s['ndof_p'], fixed_dofs=s['nfixed_dofs'],
                assemble_s=round(s['t_assemble'], 2), solve_s=round(s['t_solve'], 2), solver=s['solver'],
                process_peak_rss_mb=round(s['peak_rss_mb']), passed=bool(ok))


def stats(u, ref):
    d = np.linalg.norm(u - ref, axis=1)
    umax = float(np.linalg.norm(ref, axis=1).max())
    # best-fit scale s minimising ||s u - ref||: < 1 means u sags too little (too stiff)
    scale = float(np.sum(u * ref) / np.sum(u * u))
    return dict(relative_l2=fr.relative_l2(u, ref), max_nodal_error=float(d.max()),
                max_nodal_error_over_max_u=float(d.max() / umax), max_abs_u=float(np.linalg.norm(u, axis=1).max()),
                min_uy=float(u[:, 1].min()), best_fit_scale_to_ref=1.0 / scale if scale != 0 else None)


def existing(prefix, tag, kind):
    path = os.path.join(fr.OUT, '%s_%s_%s.csv' % (prefix, tag, kind))
    return path if os.path.exists(path) else None


def run_mesh(prefix, name, base, mesh_file, nus, args, mesh_extra=None):
    m = fr.sag_mesh(base, name)
    p, ids, mesh, fixed, ythr = m['p'], m['ids'], m['mesh'], m['fixed'], m['ythr']
    fixed_point = lambda x: x[1] >= ythr  # noqa: E731
    print('  y range [%.4f, %.4f], fixed y >= %.4f: %d vertices' % (m['ymin'], m['ymax'], ythr, fixed.sum()))
    jpath = os.path.join(fr.OUT, '%s_th.json' % prefix)
    summary = dict(
        scene='%s_th' % prefix,
        description='static linear elasticity, gravity sag of ' + name + ' in mesh units; every node with '
                    'y >= ymax - 0.1 (ymax - ymin) fixed in all three components (P2 mid-edge nodes by the '
                    'geometric rule); Taylor-Hood P2/P1 mixed reference (p = lambda div u) and the errors of '
                    'displacement-only P1 and P2 against it; displacements at the original vertices in file order',
        mesh=dict(file=mesh_file, nodes=int(len(p)), tets=int(len(m['t'])), volume=float(m['vol'].sum()),
                  y_range=[float(m['ymin']), float(m['ymax'])], y_fixed_threshold=float(ythr),
                  fixed_nodes=int(fixed.sum()), p2_nodes=int(len(p) + mesh.edges.shape[1]), **(mesh_extra or {})),
        parameters=dict(E=fr.LIVER['E'], rho=fr.LIVER['rho'], g=fr.LIVER['g'], gravity_direction=[0, -1, 0],
                        units='mesh units (consistent)', quadrature_order=4, csv_format=CSV_FMT),
        results={}, environment=fr.env_info())
    if os.path.exists(jpath):  # keep other nu already computed (runs one nu at a time add up)
        import json
        with open(jpath) as fh:
            old = json.load(fh)
        if old.get('mesh', {}).get('nodes') == summary['mesh']['nodes']:
            summary['results'] = old.get('results', {})
    ok = True
    all_nus = ((0.3,) if args.check_nu030 else ()) + tuple(nus)
    for nu in all_nus:
        tag = nu_tag(nu)
        print('-- %s %s: TH solve (%s)' % (name, tag, args.solver))
        s = solve_mixed(mesh, fr.LIVER['E'], nu, fr.LIVER['rho'], fr.LIVER['g'], fixed, fixed_point, args.solver)
        res = dict(nu=nu, lame_lambda=s['lam'], lame_mu=s['mu'])
        res['checks'] = dict(th=check_line('TH', s))
        th = s['uv']
        pv = s['p']
        res['th'] = dict(max_abs_u=float(np.linalg.norm(th, axis=1).max()), min_uy=float(th[:, 1].min()),
                         pressure_range=[float(pv.min()), float(pv.max())],
                         csv='%s_%s_th.csv' % (prefix, tag) if nu != 0.3 else None)
        sane = res['checks']['th']['passed'] and np.all(th[fixed] == 0) and th[:, 1].min() < 0
        if nu != 0.3:
            fr.write_csv(os.path.join(fr.OUT, '%s_%s_th.csv' % (prefix, tag)), ids, th, CSV_FMT)
        # displacement-only P1 and P2: committed fem_reference.py CSVs at nu 0.3 / 0.45, else solved here
        for order in (2, 1):
            kind = 'p%d' % order
            path = existing(prefix, tag, kind) if nu in (0.3, 0.45) else None
            if path:
                rid, uo = read_csv(path)
                assert np.array_equal(rid, ids)
                src = 'committed %s (fem_reference.py)' % os.path.basename(path)
                print('  [P%d] read %s' % (order, src))
            else:
                if nu == 0.3:
                    print('  [P%d] no committed nu 0.3 CSV: solving' % order)
                so = fr.solve_static(mesh, order, fr.LIVER['E'], nu, fr.LIVER['rho'], fr.LIVER['g'], fixed,
                                     fixed_point=fixed_point, solver='direct')
                res['checks']['P%d' % order] = fr.report_checks('P%d' % order, so)
                sane = sane and res['checks']['P%d' % order]['passed']
                uo = so['uv']
                src = 'solved here (SuperLU)'
                if order == 1 and nu != 0.3:  # at 0.45 only when fem_reference.py did not write it
                    fr.write_csv(os.path.join(fr.OUT, '%s_%s_p1.csv' % (prefix, tag)), ids, uo, CSV_FMT)
                    src += ', written to %s_%s_p1.csv' % (prefix, tag)
                if order == 2 and args.p2_dir:
                    os.makedirs(args.p2_dir, exist_ok=True)
                    fr.write_csv(os.path.join(args.p2_dir, '%s_%s_p2.csv' % (prefix, tag)), ids, uo, CSV_FMT)
            st = stats(uo, th)
            st['source'] = src
            res['%s_vs_th' % kind] = st
            print('  %s vs TH: relative L2 %.2f%%, max nodal error %.3e (%.1f%% of max|u_TH|), max|u| %s %.4e / TH '
                  '%.4e, best-fit scale %.3f' % (kind.upper(), 100 * st['relative_l2'], st['max_nodal_error'],
                                                100 * st['max_nodal_error_over_max_u'], kind.upper(),
                                                st['max_abs_u'], res['th']['max_abs_u'],
                                                st['best_fit_scale_to_ref']))
        if nu == 0.3:
            # two discretisations of the same compressible problem: they differ by their discretisation errors,
            # 0.7-1.5% on these meshes, 2.4% on the 922-node organ (1.3% on it refined once: README section g)
            agree = res['p2_vs_th']['relative_l2'] < 0.03
            res['checks']['th_vs_p2_at_nu030'] = dict(relative_l2=res['p2_vs_th']['relative_l2'], rule='< 3%',
                                                      passed=bool(agree))
            print('  assembly check: TH vs displacement-only P2 at nu 0.3: %.2f%% (< 3%%): %s'
                  % (100 * res['p2_vs_th']['relative_l2'], 'PASS' if agree else 'FAIL'))
            sane = sane and agree
        res['checks']['passed'] = bool(sane)
        print('  sanity: %s' % ('PASS' if sane else 'FAIL'))
        ok = ok and sane
        summary['results'][tag] = res
        summary['results'] = dict(sorted(summary['results'].items()))
        fr.write_json(jpath, summary)
    return ok


TABLE_ORDER = ('liver1k6', 'liver4k', 'liver10k', 'organ_c0133', 'organ_c0095', 'organ_c0068', 'kidney_gmsh_coarse',
               'kidney_gmsh', 'kidney_gmsh_fine', 'liver_gmsh_coarse', 'liver_gmsh', 'liver_gmsh_fine')


def print_table(out):
    """Markdown table of every {prefix}_th.json in `out` (validation/README.md section g)."""
    import glob
    import json
    rows = []
    for path in sorted(glob.glob(os.path.join(out, '*_th.json'))):
        with open(path) as fh:
            j = json.load(fh)
        prefix = os.path.basename(path)[:-len('_th.json')]
        rank = TABLE_ORDER.index(prefix) if prefix in TABLE_ORDER else len(TABLE_ORDER)
        rows.append((rank, prefix, j))
    print('| mesh | nodes | nu | **P1 vs TH** | P2 vs TH | P1 max nodal error | P2 max nodal error | max \\|u\\| TH '
          '| P1 / P2 best-fit scale | TH dofs | TH solve [s] |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for _, prefix, j in sorted(rows, key=lambda r: r[0]):
        for tag, r in j['results'].items():
            c = r['checks']['th']
            p1, p2 = r['p1_vs_th'], r['p2_vs_th']
            print('| %s | %s | %g | **%.1f%%** | %.1f%% | %.1f%% | %.1f%% | %.4e | %.2f / %.2f | %s | %.0f |'
                  % (prefix, format(j['mesh']['nodes'], ','), r['nu'], 100 * p1['relative_l2'],
                     100 * p2['relative_l2'], 100 * p1['max_nodal_error_over_max_u'],
                     100 * p2['max_nodal_error_over_max_u'], r['th']['max_abs_u'], p1['best_fit_scale_to_ref'],
                     p2['best_fit_scale_to_ref'], format(c['dofs'], ','), c['solve_s']))


GMSH_MESHES = ('kidney_gmsh', 'liver_gmsh', 'kidney_gmsh_coarse', 'kidney_gmsh_fine', 'liver_gmsh_coarse',
               'liver_gmsh_fine')


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--scene', default=None,
                    choices=['liver1k6', 'liver4k', 'liver10k', 'organ', *GMSH_MESHES, 'all'])
    ap.add_argument('--nu', type=float, nargs='+', default=list(NUS))
    ap.add_argument('--check-nu030', action='store_true',
                    help='also solve TH at nu 0.3 and compare with displacement-only P2 (assembly check)')
    ap.add_argument('--solver', choices=['direct', 'minres'], default='direct')
    ap.add_argument('--organ-cell', type=float, nargs='+', default=list(fr.ORGAN_CELLS))
    ap.add_argument('--organ-dir', default=fr.ORGAN_DIR)
    ap.add_argument('--mesh-dir', default=fr.MESH_DIR)
    ap.add_argument('--out', default=fr.OUT)
    ap.add_argument('--p2-dir', default=None, help='also write the displacement-only P2 CSVs solved here to DIR')
    ap.add_argument('--table', action='store_true', help='print the markdown table of the JSONs in --out and exit')
    args = ap.parse_args()
    if args.table:
        print_table(os.path.abspath(args.out))
        return 0
    if args.scene is None:
        ap.error('--scene is required (or --table)')
    fr.OUT = os.path.abspath(args.out)
    fr.DIRECT_ORDERING = 'symmetric-mmd'  # also for the displacement-only P1/P2 solves made here
    os.makedirs(fr.OUT, exist_ok=True)
    t0 = time.perf_counter()
    ok = True
    sc = args.scene
    for key, mesh in (('liver1k6', 'liver_1k6'), ('liver4k', 'liver_4k'), ('liver10k', 'liver_10k')):
        if sc in (key, 'all'):
            ok = run_mesh(key, mesh, os.path.join(args.mesh_dir, mesh), '%s.node/.ele (data/meshes)' % mesh,
                          args.nu, args) and ok
    if sc in ('organ', 'all'):
        for cell in args.organ_cell:
            base = fr.organ_mesh(cell, args.organ_dir)
            label = 'c%04d' % round(cell * 1e4)
            extra = dict(cell_m=cell, scale_to_mesh_units=fr.ORGAN_SCALE,
                         generator='tissuesim::mesh::organ_with_cell(%r) x %g, `cargo run --release --example '
                                   'organ_check -- export DIR %r`' % (cell, fr.ORGAN_SCALE, cell),
                         sha256={'organ.node': fr.sha256(base + '.node'), 'organ.ele': fr.sha256(base + '.ele')})
            ok = run_mesh('organ_%s' % label, 'the organ of cell %g m (x %g)' % (cell, fr.ORGAN_SCALE), base,
                          'organ.node/.ele (examples/organ_check.rs export, cell %g)' % cell, args.nu, args,
                          extra) and ok
    for mesh in GMSH_MESHES:
        if sc in (mesh, 'all'):
            base = os.path.join(args.mesh_dir, mesh)
            extra = dict(sha256={mesh + '.node': fr.sha256(base + '.node'), mesh + '.ele': fr.sha256(base + '.ele')})
            ok = run_mesh(mesh, mesh, base, '%s.node/.ele (data/meshes, gmsh)' % mesh, args.nu,
                          args, extra) and ok
    print('== all checks %s (%.0f s, process peak RSS %.0f MB)'
          % ('PASSED' if ok else 'FAILED', time.perf_counter() - t0, rss_mb()))
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
