#!/usr/bin/env python3
"""Organ meshes from a second mesher (gmsh, PyPI package pinned in validation/setup_venv.sh), written as TetGen
.node/.ele (0-based, positively oriented tets, only the vertices the tets use) into data/meshes/.

  kidney_gmsh  the project's own kidney-like shape: an ellipsoid (semi-axes 3.0 x 1.7 x 1.3 mesh units) with a
               hilum groove (a second ellipsoid cut away) on its lower side, built with gmsh's OpenCASCADE kernel
               and meshed by gmsh's Delaunay 3-D mesher (+ Netgen optimiser).  Licence: the project's.
  liver_gmsh   SOFA's visual liver surface (data/meshes/liver-smooth.obj, LGPL-2.1): the OBJ triangles are read,
               duplicate vertices merged, the surface reparametrised by gmsh (classifySurfaces/createGeometry),
               remeshed and volume-meshed by gmsh.  Licence: LGPL-2.1 (derived from SOFA's file).

  *_coarse, *_fine  each organ at element size x sqrt(2) and / sqrt(2): the refinement families of the
               convergence study.

Usage:  build/venv-validation/bin/python validation/gmsh_organs.py [kidney_gmsh] [liver_gmsh] [...] [--out data/meshes]
The meshes are deterministic for a given gmsh version (4.15.2); data/meshes/README.md lists their SHA-256.
"""
import argparse
import math
import os
import sys

import gmsh
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def tet_mesh():
    """The current gmsh model's linear tets: (p (N,3), t (M,4)) compacted to used nodes, positively oriented."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = coords.reshape(-1, 3)
    types, _, conn = gmsh.model.mesh.getElements(dim=3)
    assert list(types) == [4], 'only linear tets expected, got element types %s' % list(types)
    tt = conn[0].reshape(-1, 4).astype(np.int64)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    t = index[tt]
    used = np.unique(t)
    remap = np.full(len(tags), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    p = coords[used]
    t = remap[t]
    a, b, c = (p[t[:, k]] - p[t[:, 0]] for k in (1, 2, 3))
    vol = np.einsum('ij,ij->i', np.cross(a, b), c) / 6.0
    neg = vol < 0
    t[neg] = t[neg][:, [0, 2, 1, 3]]
    return p, t


def quality(p, t):
    """Volume, and the radius ratio 3 r_in / r_circ of each tet (1 = regular)."""
    a, b, c = (p[t[:, k]] - p[t[:, 0]] for k in (1, 2, 3))
    vol = np.einsum('ij,ij->i', np.cross(a, b), c) / 6.0
    faces = [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
    area = sum(0.5 * np.linalg.norm(np.cross(p[t[:, j]] - p[t[:, i]], p[t[:, k]] - p[t[:, i]]), axis=1)
               for i, j, k in faces)
    r_in = 3 * vol / area
    # circumradius: |a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b) over 12 V
    num = (np.sum(a * a, 1)[:, None] * np.cross(b, c) + np.sum(b * b, 1)[:, None] * np.cross(c, a)
           + np.sum(c * c, 1)[:, None] * np.cross(a, b))
    r_c = np.linalg.norm(num, axis=1) / (12 * vol)
    return vol, 3 * r_in / r_c


def write_tetgen(base, p, t, comment):
    with open(base + '.node', 'w') as fh:
        fh.write('%d  3  0  0\n' % len(p))
        for i, x in enumerate(p):
            fh.write('%d  %.17g  %.17g  %.17g\n' % (i, *x))
        fh.write('# %s\n' % comment)
    with open(base + '.ele', 'w') as fh:
        fh.write('%d  4  0\n' % len(t))
        for i, e in enumerate(t):
            fh.write('%d  %d  %d  %d  %d\n' % (i, *e))
        fh.write('# %s\n' % comment)


def mesh_volume(size):
    gmsh.option.setNumber('Mesh.MeshSizeMax', size)
    gmsh.option.setNumber('Mesh.MeshSizeMin', 0.5 * size)
    gmsh.option.setNumber('Mesh.Algorithm3D', 1)  # Delaunay
    gmsh.option.setNumber('Mesh.Optimize', 1)
    gmsh.option.setNumber('Mesh.OptimizeNetgen', 1)
    gmsh.option.setNumber('General.NumThreads', 1)
    gmsh.option.setNumber('Mesh.RandomSeed', 1)
    gmsh.model.mesh.generate(3)


def kidney(size):
    gmsh.model.add('kidney')
    occ = gmsh.model.occ
    body = occ.addSphere(0, 0, 0, 1.0)
    occ.dilate([(3, body)], 0, 0, 0, 3.0, 1.7, 1.3)
    notch = occ.addSphere(0, 0, 0, 1.0)
    occ.dilate([(3, notch)], 0, 0, 0, 0.9, 0.8, 2.0)
    occ.translate([(3, notch)], 0.2, -1.75, 0.3)
    occ.cut([(3, body)], [(3, notch)])
    occ.rotate(occ.getEntities(3), 0, 0, 0, 0, 0, 1, math.radians(8))  # tilt: no mirror symmetry in x
    occ.translate(occ.getEntities(3), -1.0, 2.6, 0.5)  # roughly where the livers are (y from ~0.9 up)
    occ.synchronize()
    mesh_volume(size)
    return 'kidney-like ellipsoid 3.0 x 1.7 x 1.3 with a hilum groove, gmsh %s OCC + Delaunay, size %g' % (
        gmsh.__version__, size)


def read_obj(path):
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            s = line.split()
            if not s:
                continue
            if s[0] == 'v':
                v.append([float(x) for x in s[1:4]])
            elif s[0] == 'f':
                f.append([int(x.split('/')[0]) - 1 for x in s[1:4]])
    return np.array(v), np.array(f, dtype=np.int64)


def boundary_of_tetgen(base):
    """Boundary triangles (faces of exactly one tet) of a TetGen mesh: (vertices, triangles) compacted."""
    sys.path.insert(0, HERE)
    from fem_reference import read_tetgen
    p, t, _ = read_tetgen(base)
    faces = np.concatenate([t[:, [0, 1, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 3]], t[:, [1, 2, 3]]])
    opposite = np.concatenate([t[:, 3], t[:, 2], t[:, 1], t[:, 0]])
    key = np.sort(faces, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    one = cnt[inv.ravel()] == 1
    f, d = faces[one], opposite[one]
    # orient every triangle outwards (normal away from the tet's fourth vertex)
    n = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    inward = np.einsum('ij,ij->i', n, p[d] - p[f[:, 0]]) > 0
    f[inward] = f[inward][:, [0, 2, 1]]
    used = np.unique(f)
    remap = np.full(len(p), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return p[used], remap[f]


def liver(size, angle_deg=60.0):
    if LIVER_SURFACE == 'obj':
        v, f = read_obj(os.path.join(REPO, 'data', 'meshes', 'liver-smooth.obj'))
    else:  # the boundary of liver_31k: SOFA's surface as repaired for the TetGen livers
        v, f = boundary_of_tetgen(os.path.join(REPO, 'data', 'meshes', 'liver_31k'))
    # merge duplicate vertices (OBJ exports repeat them at texture seams)
    key = np.round(v / 1e-9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    v, f = v[first], inv.ravel()[f]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    gmsh.model.add('liver')
    gmsh.model.addDiscreteEntity(2, 1)
    gmsh.model.mesh.addNodes(2, 1, np.arange(1, len(v) + 1), v.ravel())
    gmsh.model.mesh.addElementsByType(1, 2, [], (f + 1).ravel())
    gmsh.model.mesh.removeDuplicateNodes()
    gmsh.model.mesh.classifySurfaces(math.radians(angle_deg), True, True, math.pi)
    gmsh.model.mesh.createGeometry()
    surfaces = [s[1] for s in gmsh.model.getEntities(2)]
    loop = gmsh.model.geo.addSurfaceLoop(surfaces)
    gmsh.model.geo.addVolume([loop])
    gmsh.model.geo.synchronize()
    mesh_volume(size)
    return ('SOFA liver surface (%s: %d vertices, %d triangles) reparametrised (classifySurfaces %g deg) '
            'and remeshed by gmsh %s, Delaunay, size %g' % (LIVER_SURFACE, len(v), len(f), angle_deg, gmsh.__version__, size))


LIVER_SURFACE = 'liver_31k'  # 'obj' = liver-smooth.obj itself: self-intersecting, gmsh's 3-D mesher refuses it
# The two organs, and each at a coarser and a finer size (element size x sqrt(2) and / sqrt(2)): the
# refinement families of the convergence study (docs/VALIDATION.md, validation/README.md g).
BUILDERS = dict(kidney_gmsh=(kidney, 0.22), liver_gmsh=(liver, 0.28),
                kidney_gmsh_coarse=(kidney, 0.31), kidney_gmsh_fine=(kidney, 0.155),
                liver_gmsh_coarse=(liver, 0.4), liver_gmsh_fine=(liver, 0.2))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('names', nargs='*', default=list(BUILDERS))
    ap.add_argument('--out', default=os.path.join(REPO, 'data', 'meshes'))
    ap.add_argument('--size', type=float, default=None, help='override the target element size (mesh units)')
    args = ap.parse_args()
    for name in args.names:
        build, size = BUILDERS[name]
        gmsh.initialize(['-noenv'])
        gmsh.option.setNumber('General.Terminal', 0)
        try:
            desc = build(args.size or size)
            p, t = tet_mesh()
        finally:
            gmsh.finalize()
        vol, q = quality(p, t)
        print('%s: %d nodes, %d tets, volume %.4f, min tet volume %.3e, radius ratio min %.3f / mean %.3f; '
              'x [%.2f, %.2f] y [%.2f, %.2f] z [%.2f, %.2f]'
              % (name, len(p), len(t), vol.sum(), vol.min(), q.min(), q.mean(),
                 *[v for k in range(3) for v in (p[:, k].min(), p[:, k].max())]))
        assert (vol > 0).all()
        write_tetgen(os.path.join(args.out, name), p, t, desc)
    return 0


if __name__ == '__main__':
    sys.exit(main())
