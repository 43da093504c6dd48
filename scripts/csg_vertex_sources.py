#!/usr/bin/env python3
"""Where a Boolean result's vertices come from: the inputs' vertices, the
points where the two surfaces cross, or neither (points an octree wall or
another cut added).

Outside CI (needs numpy, scipy, trimesh and, for --manifold, manifold3d):

    python3 scripts/csg_vertex_sources.py A.obj B.obj RESULT.obj [--manifold union]

With --manifold OP it also computes OP with manifold3d on the same inputs
and sorts that result's vertices the same way. A closed triangle mesh has
two triangles per vertex, so the vertices of the third kind account for
the extra triangles of one result over another.
"""

import argparse

import numpy as np
import trimesh
from scipy.spatial import cKDTree


def sources(a, b, r):
    v = r.vertices
    tol = 1e-6 * np.abs(v).max()
    near, _ = cKDTree(np.vstack([a.vertices, b.vertices])).query(v)
    original = near < tol
    _, da, _ = trimesh.proximity.closest_point(a, v)
    _, db, _ = trimesh.proximity.closest_point(b, v)
    crossing = ~original & (da < tol) & (db < tol)
    other = ~original & ~crossing
    return len(v), int(original.sum()), int(crossing.sum()), int(other.sum()), len(r.faces)


def manifold(a, b, op):
    import manifold3d as m3

    def solid(m):
        return m3.Manifold(m3.Mesh(np.asarray(m.vertices, np.float32), np.asarray(m.faces, np.uint32)))

    x, y = solid(a), solid(b)
    r = {"union": x + y, "intersection": x ^ y, "difference": x - y}[op].to_mesh()
    return trimesh.Trimesh(np.asarray(r.vert_properties)[:, :3], np.asarray(r.tri_verts), process=False)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("result")
    ap.add_argument("--manifold", choices=["union", "intersection", "difference"])
    args = ap.parse_args()
    a, b = (trimesh.load(p, process=False) for p in (args.a, args.b))
    rows = [("result", trimesh.load(args.result, process=False))]
    if args.manifold:
        rows.append(("manifold3d", manifold(a, b, args.manifold)))
    print(f"{'':12} {'vertices':>9} {'inputs':>9} {'crossings':>9} {'other':>9} {'triangles':>9}")
    for name, r in rows:
        print(f"{name:12} " + " ".join(f"{n:9d}" for n in sources(a, b, r)))


if __name__ == "__main__":
    main()
