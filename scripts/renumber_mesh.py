#!/usr/bin/env python3
"""Renumber a TetGen mesh's nodes for locality, to measure what the step gains from it
(docs/PERFORMANCE.md, "Particle renumbering, measured, not built").

    python3 scripts/renumber_mesh.py rcm|morton OUT_DIR data/meshes/liver_4k [...]

writes OUT_DIR/liver_4k.node and .ele with the nodes in reverse Cuthill-McKee order (breadth
first over the tetrahedra's edges from a node of least degree, neighbours by increasing degree,
the order reversed) or Morton order (a 10-bit-per-axis Z curve over the bounding box), and
prints the mean |i - j| over the tetrahedra's node pairs before and after. Point the bench at
the copies with TISSUESIM_MESHES=OUT_DIR. Standard library only.
"""
import collections
import os
import sys


def read_table(path):
    """The non-empty rows of a TetGen file, comments removed, split into fields."""
    with open(path) as f:
        rows = [line.split("#")[0].split() for line in f]
    return [r for r in rows if r]


def rcm_order(n, adjacency):
    degree = [len(a) for a in adjacency]
    seen = [False] * n
    order = []
    for start in sorted(range(n), key=lambda k: degree[k]):
        if seen[start]:
            continue
        seen[start] = True
        queue = collections.deque([start])
        while queue:
            v = queue.popleft()
            order.append(v)
            for w in sorted(adjacency[v], key=lambda k: degree[k]):
                if not seen[w]:
                    seen[w] = True
                    queue.append(w)
    order.reverse()
    return order


def morton_order(points):
    lo = [min(p[a] for p in points) for a in range(3)]
    hi = [max(p[a] for p in points) for a in range(3)]

    def key(k):
        cell = [int((points[k][a] - lo[a]) / (hi[a] - lo[a] + 1e-300) * 1023) for a in range(3)]
        code = 0
        for bit in range(10):
            for a in range(3):
                code |= ((cell[a] >> bit) & 1) << (3 * bit + a)
        return code

    return sorted(range(len(points)), key=key)


def mean_index_distance(tets, index):
    total = sum(abs(index[a] - index[b]) for t in tets for a in t for b in t)
    return total / (16 * len(tets))


def renumber(method, stem, out_dir):
    node_rows = read_table(stem + ".node")
    n = int(node_rows[0][0])
    base = int(node_rows[1][0])
    points = [tuple(map(float, r[1:4])) for r in node_rows[1 : 1 + n]]
    ele_rows = read_table(stem + ".ele")
    count, per = int(ele_rows[0][0]), int(ele_rows[0][1])
    tets = [[int(v) - base for v in r[1 : 1 + per]] for r in ele_rows[1 : 1 + count]]
    adjacency = [set() for _ in range(n)]
    for t in tets:
        for a in t:
            adjacency[a].update(b for b in t if b != a)
    order = rcm_order(n, adjacency) if method == "rcm" else morton_order(points)
    new_index = [0] * n
    for i, old in enumerate(order):
        new_index[old] = i
    name = os.path.basename(stem)
    print(
        f"{name} {method}: mean |i - j| {mean_index_distance(tets, list(range(n))):.0f} -> "
        f"{mean_index_distance(tets, new_index):.0f}"
    )
    with open(os.path.join(out_dir, name + ".node"), "w") as f:
        f.write(f"{n} 3 0 0\n")
        for i, old in enumerate(order):
            x, y, z = points[old]
            f.write(f"{i} {x!r} {y!r} {z!r}\n")
    with open(os.path.join(out_dir, name + ".ele"), "w") as f:
        f.write(f"{count} 4 0\n")
        for k, t in enumerate(tets):
            f.write(f"{k} " + " ".join(str(new_index[v]) for v in t) + "\n")


def main():
    if len(sys.argv) < 4 or sys.argv[1] not in ("rcm", "morton"):
        sys.exit(__doc__)
    method, out_dir = sys.argv[1], sys.argv[2]
    os.makedirs(out_dir, exist_ok=True)
    for stem in sys.argv[3:]:
        renumber(method, stem, out_dir)


if __name__ == "__main__":
    main()
