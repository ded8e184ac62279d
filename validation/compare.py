#!/usr/bin/env python3
"""Compare node displacements of a solver run against a reference (both CSV `node,ux,uy,uz`).

    python3 validation/compare.py SOLVER.csv REFERENCE.csv [--max-rel-l2 0.03]

Prints the relative L2 error over nodes, ||u - u_ref|| / ||u_ref|| (Frobenius norm of the N x 3 arrays, i.e.
the sum over nodes of the squared nodal error vectors), and the max-norm error max_i |u_i - u_ref,i| (Euclidean
norm of the nodal error vector), absolute and relative to max_i |u_ref,i|. Rows are matched by the `node`
column, so the order of the rows does not matter, but both files must hold the same set of nodes. With
--max-rel-l2 the exit status is 1 when the relative L2 error exceeds the bound.

Library use (numpy only):
    from compare import read_csv, relative_l2, max_norm, compare_files
    relative_l2(a, b)       # a, b: (N, 3) arrays, b the reference
"""
import argparse
import sys

import numpy as np


def read_csv(path):
    """Read `node,ux,uy,uz`. Returns (node ids (N,) int64, displacements (N,3) float64), in file order."""
    with open(path) as fh:
        header = fh.readline().strip().replace(' ', '').lower()
    if header != 'node,ux,uy,uz':
        raise ValueError('%s: header must be "node,ux,uy,uz", got %r' % (path, header))
    data = np.loadtxt(path, delimiter=',', skiprows=1, ndmin=2)
    if data.shape[1] != 4:
        raise ValueError('%s: expected 4 columns, got %d' % (path, data.shape[1]))
    ids = data[:, 0].astype(np.int64)
    if not np.array_equal(ids, data[:, 0]):
        raise ValueError('%s: node ids must be integers' % path)
    if len(np.unique(ids)) != len(ids):
        raise ValueError('%s: duplicate node ids' % path)
    u = data[:, 1:4]
    if not np.isfinite(u).all():
        raise ValueError('%s: non-finite displacement' % path)
    return ids, u


def relative_l2(a, b):
    """Relative L2 error of a against the reference b: ||a - b|| / ||b||, over all nodes and components."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise ValueError('shape mismatch %s vs %s' % (a.shape, b.shape))
    nb = np.linalg.norm(b)
    if nb == 0:
        raise ValueError('reference displacement is identically zero')
    return float(np.linalg.norm(a - b) / nb)


def max_norm(a, b):
    """Largest nodal error max_i |a_i - b_i| (Euclidean per node) and the same relative to max_i |b_i|."""
    a, b = np.asarray(a, dtype=float).reshape(len(a), -1), np.asarray(b, dtype=float).reshape(len(b), -1)
    err = np.linalg.norm(a - b, axis=1)
    i = int(np.argmax(err))
    return float(err[i]), float(err[i] / np.linalg.norm(b, axis=1).max()), i


def align(ids_a, a, ids_b, b):
    """Reorder a to the node order of b (matching on the node ids); the node sets must be equal."""
    if np.array_equal(ids_a, ids_b):
        return a
    if set(ids_a.tolist()) != set(ids_b.tolist()):
        only_a = sorted(set(ids_a.tolist()) - set(ids_b.tolist()))[:5]
        only_b = sorted(set(ids_b.tolist()) - set(ids_a.tolist()))[:5]
        raise ValueError('node sets differ (e.g. only in solver: %s, only in reference: %s)' % (only_a, only_b))
    pos = {int(n): k for k, n in enumerate(ids_a)}
    return a[[pos[int(n)] for n in ids_b]]


def compare_files(solver_csv, reference_csv):
    """Return a dict with rel_l2, max_abs, max_rel, worst_node, nodes, ref_max_abs_u, solver_max_abs_u."""
    ids_s, us = read_csv(solver_csv)
    ids_r, ur = read_csv(reference_csv)
    us = align(ids_s, us, ids_r, ur)
    mabs, mrel, i = max_norm(us, ur)
    return dict(nodes=len(ur), rel_l2=relative_l2(us, ur), max_abs=mabs, max_rel=mrel, worst_node=int(ids_r[i]),
                ref_max_abs_u=float(np.linalg.norm(ur, axis=1).max()),
                solver_max_abs_u=float(np.linalg.norm(us, axis=1).max()))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('solver_csv')
    ap.add_argument('reference_csv')
    ap.add_argument('--max-rel-l2', type=float, default=None, help='fail (exit 1) above this relative L2 error')
    args = ap.parse_args(argv)
    r = compare_files(args.solver_csv, args.reference_csv)
    print('nodes %d  rel_L2 %.6f (%.3f%%)  max_abs %.6e  max_rel %.6f (node %d)  max|u| solver %.6e ref %.6e'
          % (r['nodes'], r['rel_l2'], 100 * r['rel_l2'], r['max_abs'], r['max_rel'], r['worst_node'],
             r['solver_max_abs_u'], r['ref_max_abs_u']))
    if args.max_rel_l2 is not None and r['rel_l2'] > args.max_rel_l2:
        print('FAIL: rel_L2 %.6f > %.6f' % (r['rel_l2'], args.max_rel_l2))
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
