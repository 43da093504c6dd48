#!/usr/bin/env python3
"""Compare `shadow csg` (exact BSP merging) with manifold3d on the same inputs.

Outside CI. Generates the inputs of `bsp-core/benches/csg.rs` (UV spheres of
~1k / ~10k / ~100k triangles against a copy rotated 5 degrees and shifted by
0.3 radius; data/meshes/bunny.obj against a shifted copy), writes them as OBJ
files into a temp dir, and for each operation:

* runs `target/dist/shadow csg OP A.obj B.obj -o out.obj --stats`
  `--our-reps` times and takes the median of each phase it prints;
* loads the same OBJ vertex/triangle arrays into manifold3d (outside the
  timing) and times, median of `--reps`: Manifold construction of both
  operands, and the boolean forced by `to_mesh()` (manifold is lazy).

Prints a table: ours (validation of both meshes as closed, oriented
2-manifolds, snap/import of both into solids, the boolean, boundary+mesh
with its watertightness check), manifold (construct, which checks the
meshes too, and boolean+to_mesh), and the ratios ours/theirs for
boolean+mesh vs boolean and end to end (validate+snap+boolean+mesh vs
construct+boolean; file reading and writing excluded on both sides).
`total` is the CLI's own wall time with loading and writing.

On a host whose speed drifts over minutes, the ratio of a block of our runs
to a block of theirs moves with the drift; `--paired K` then runs K rounds
of one run each, alternating, and prints the median and range of the
per-round ratios.

    pip install manifold3d numpy
    cargo build --profile dist -p shadow-cli
    python3 scripts/manifold_compare.py --sizes 1000 10000 --bunny
"""
import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import manifold3d
from manifold3d import Manifold, Mesh

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Keep in sync with bsp-core/benches/csg.rs.
ANGLE_DEG = 5.0
AXIS = (1.0, 2.0, 3.0)
SHIFT = (0.3, 0.1, 0.05)  # in radii (spheres) / in half the largest extent (bunny)


def sphere_stacks(n):
    """Stacks of the UV sphere of about n triangles (slices = 2 stacks)."""
    return max(3, math.floor(math.sqrt(n / 4.0) + 0.5))


def uv_sphere(n):
    """Unit UV sphere: 2 poles + (s-1) rings of 2s vertices; 4 s (s-1)
    triangles, outward (counter-clockwise seen from outside)."""
    s = sphere_stacks(n)
    m = 2 * s
    verts = [(0.0, 0.0, 1.0)]
    for i in range(1, s):
        th = math.pi * i / s
        for j in range(m):
            ph = 2.0 * math.pi * j / m
            verts.append((math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)))
    verts.append((0.0, 0.0, -1.0))
    south = len(verts) - 1
    ring = lambda i, j: 1 + (i - 1) * m + (j % m)
    tris = []
    for j in range(m):
        tris.append((0, ring(1, j), ring(1, j + 1)))
    for i in range(1, s - 1):
        for j in range(m):
            a, b = ring(i, j), ring(i, j + 1)
            c, d = ring(i + 1, j + 1), ring(i + 1, j)
            tris.append((a, d, c))
            tris.append((a, c, b))
    for j in range(m):
        tris.append((ring(s - 1, j), south, ring(s - 1, j + 1)))
    return verts, tris


def rotate(v):
    """Rodrigues rotation by ANGLE_DEG about AXIS."""
    k = np.array(AXIS) / np.linalg.norm(AXIS)
    a = math.radians(ANGLE_DEG)
    v = np.asarray(v, dtype=np.float64)
    return (v * math.cos(a) + np.cross(k, v) * math.sin(a)
            + np.outer(v @ k, k) * (1 - math.cos(a)))


def read_obj(path):
    verts, tris = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "f":
                idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                for k in range(1, len(idx) - 1):
                    tris.append((idx[0], idx[k], idx[k + 1]))
    return verts, tris


def write_obj(path, verts, tris):
    with open(path, "w") as f:
        for v in verts:
            f.write("v %r %r %r\n" % (float(v[0]), float(v[1]), float(v[2])))
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def cases(args):
    for n in args.sizes:
        v, t = uv_sphere(n)
        a = np.array(v)
        b = rotate(a) + np.array(SHIFT)
        yield "sphere %d" % len(t), (a, t), (b, t)
    if args.bunny:
        v, t = read_obj(os.path.join(ROOT, "data/meshes/bunny.obj"))
        a = np.array(v)
        half = (a.max(0) - a.min(0)).max() / 2
        yield "bunny %d" % len(t), (a, t), (a + np.array(SHIFT) * half, t)


def run_ours(cli, op, pa, pb, out, reps, timeout):
    runs = []
    for _ in range(reps):
        r = subprocess.run([cli, "csg", op, pa, pb, "-o", out, "--stats"],
                           capture_output=True, text=True, timeout=timeout)
        if r.returncode != 0:
            raise RuntimeError("shadow csg failed: " + r.stderr.strip())
        ph, nodes, tris = {}, None, None
        in_time = False
        for line in r.stdout.splitlines():
            if line.startswith("octree:"):
                nodes = line.split(":", 1)[1].strip().split(";")[0]
            elif line.startswith("output:"):
                tris = int(line.split()[1])
            elif line.startswith("time (ms):"):
                in_time = True
            elif in_time and line.startswith("  "):
                name, val = line.strip().rsplit(None, 1)
                ph[name.strip()] = float(val)
        runs.append(ph)
    med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
    return med, nodes, tris


def arrays_of(verts, tris):
    """The input as manifold3d takes it: `float32` positions and `uint32`
    triangles (made outside the timing: turning a Python list of 100k
    tuples into an array takes about 17 ms, which is not manifold's work)."""
    return (np.ascontiguousarray(verts, dtype=np.float32),
            np.ascontiguousarray(tris, dtype=np.uint32))


def manifold_of(verts, tris):
    """A Manifold from the arrays of `arrays_of`."""
    mesh = Mesh(vert_properties=verts, tri_verts=tris)
    m = Manifold(mesh)
    st = m.status()
    if str(st) not in ("Error.NoError", "NoError") and "NoError" not in str(st):
        raise RuntimeError("manifold3d rejects the input: %s" % st)
    return m


def run_theirs(op, a, b, reps):
    fn = {"union": lambda x, y: x + y,
          "intersection": lambda x, y: x ^ y,
          "difference": lambda x, y: x - y}[op]
    cons, boo, ntri = [], [], None
    a, b = arrays_of(*a), arrays_of(*b)
    for _ in range(reps):
        t0 = time.perf_counter()
        ma, mb = manifold_of(*a), manifold_of(*b)
        ma.num_tri(), mb.num_tri()
        t1 = time.perf_counter()
        r = fn(ma, mb)
        mesh = r.to_mesh()
        t2 = time.perf_counter()
        ntri = len(np.asarray(mesh.tri_verts))
        cons.append((t1 - t0) * 1e3)
        boo.append((t2 - t1) * 1e3)
    return statistics.median(cons), statistics.median(boo), ntri


def ours_of(ph):
    """The compared phases of one run of ours (see the table's `ours`)."""
    return (ph.get("validate", 0) + ph.get("snap/import", 0) + ph.get("boolean", 0)
            + ph.get("boundary+mesh", 0) + ph.get("check", 0))


def run_paired(args, op, pa, pb, out, a, b):
    """`args.paired` rounds of one run of ours and one of theirs, the
    first of the pair alternating: (rounds, our median, their median,
    median ratio, lowest, highest, rounds with a ratio below 1)."""
    ours, theirs, ratios = [], [], []
    for k in range(args.paired):
        def one_ours():
            return ours_of(run_ours(args.cli, op, pa, pb, out, 1, args.timeout)[0])

        def one_theirs():
            mc, mb, _ = run_theirs(op, a, b, 1)
            return mc + mb

        if k % 2 == 0:
            o, t = one_ours(), one_theirs()
        else:
            t, o = one_theirs(), one_ours()
        ours.append(o)
        theirs.append(t)
        ratios.append(o / t)
    return (args.paired, statistics.median(ours), statistics.median(theirs),
            statistics.median(ratios), min(ratios), max(ratios),
            sum(r < 1 for r in ratios))


def sign_test(below, k):
    """One-sided sign test: the chance of `below` or more of `k` rounds
    below 1 if ours and theirs were equally fast (each round a coin)."""
    return sum(math.comb(k, j) for j in range(below, k + 1)) / 2 ** k


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[1000, 10000])
    ap.add_argument("--bunny", action="store_true")
    ap.add_argument("--ops", nargs="*", default=["union", "intersection", "difference"])
    ap.add_argument("--reps", type=int, default=5, help="manifold3d repetitions (median)")
    ap.add_argument("--our-reps", type=int, default=3, help="shadow csg runs (median)")
    ap.add_argument("--cli", default=os.path.join(ROOT, "target/dist/shadow"))
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--keep", help="write the OBJ files here instead of a temp dir")
    ap.add_argument("--paired", type=int, default=0, metavar="K",
                    help="then K rounds of one run each, ours and theirs alternating "
                         "(which goes first too): the median and range of the "
                         "per-round ratios, which a host whose speed drifts over "
                         "minutes moves less than the ratio of two blocks of runs")
    args = ap.parse_args()

    from importlib.metadata import version
    print("manifold3d %s, numpy %s" % (version("manifold3d"), np.__version__))
    hdr = ("%-14s %-12s %9s %9s %9s %9s %9s | %9s %9s | %7s %7s | %s"
           % ("case", "op", "val+snap", "boolean", "mesh", "ours", "total", "m.constr", "m.bool",
              "r.b+m", "r.all", "octree / out tris ours,theirs"))
    print(hdr)
    print("-" * len(hdr))
    paired = []
    with tempfile.TemporaryDirectory() as tmp:
        d = args.keep or tmp
        os.makedirs(d, exist_ok=True)
        for name, a, b in cases(args):
            tag = name.replace(" ", "_")
            pa, pb = os.path.join(d, tag + "_A.obj"), os.path.join(d, tag + "_B.obj")
            write_obj(pa, *a)
            write_obj(pb, *b)
            for op in args.ops:
                out = os.path.join(d, "%s_%s_out.obj" % (tag, op))
                ph, nodes, tris = run_ours(args.cli, op, pa, pb, out, args.our_reps, args.timeout)
                mc, mb, mt = run_theirs(op, a, b, args.reps)
                build = ph.get("validate", 0) + ph.get("snap/import", 0)
                merge = ph.get("boolean", 0)
                # (the watertightness check is inside boundary+mesh since
                # 363195e; older builds print it as a phase of its own)
                mesh = ph.get("boundary+mesh", 0) + ph.get("check", 0)
                ours = ours_of(ph)
                print("%-14s %-12s %9.2f %9.2f %9.2f %9.2f %9.2f | %9.2f %9.2f | %7.2f %7.2f | %s / %s,%s"
                      % (name, op, build, merge, mesh, ours, ph.get("total", 0), mc, mb,
                         (merge + mesh) / mb, ours / (mc + mb), nodes, tris, mt))
                sys.stdout.flush()
                if args.paired:
                    paired.append((name, op) + run_paired(args, op, pa, pb, out, a, b))
    if paired:
        print("paired rounds (ours = validate+snap+boolean+mesh, theirs = construct+boolean, one "
              "run each per round, alternating):")
        for name, op, k, o, t, med, lo, hi, below in paired:
            print("%-14s %-12s %3d rounds: ours %8.2f ms, theirs %8.2f ms (medians); "
                  "ratio median %.3f (%.3f-%.3f); below 1 in %d (sign test p = %.2g)"
                  % (name, op, k, o, t, med, lo, hi, below, sign_test(below, k)))
    print("times in ms (medians); ours = validate + snap/import + boolean + boundary+mesh+check "
          "(file IO excluded); total = the CLI's whole run;")
    print("r.b+m = (boolean+mesh)/manifold boolean; r.all = ours/(manifold construct+boolean)")


if __name__ == "__main__":
    main()
