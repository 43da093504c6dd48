#!/usr/bin/env python3
"""Booleans of a part read back with its whole: every case must succeed,
and the exact volumes must add up.

Outside CI (it needs numpy). For random UV spheres of 800–4,000 triangles
(``manifold_compare.uv_sphere``) and random boxes, the part is the sphere
less (or cut to) the box, written as OBJ by ``shadow csg``; then, with the
part read back (its vertices on the first run's grid, a step away from the
sphere's on the second's: the surfaces nearly coincide), checks

    |S ∪ P| = |S| + |P − S|     and     |S ∩ P| = |P| − |P − S|

with the volumes ``--stats`` prints (exact, rounded once). Prints the
cases that fail and a count.

    python3 scripts/readback_check.py [--bin target/release/shadow] [--cases 40] [--seed 7]
"""
import argparse
import os
import random
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from manifold_compare import uv_sphere, write_obj  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def box(path, lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(1, 4, 3, 2), (5, 6, 7, 8), (1, 2, 6, 5), (2, 3, 7, 6), (3, 4, 8, 7), (4, 1, 5, 8)]
    with open(path, "w") as out:
        out.write("".join("v %r %r %r\n" % p for p in v))
        out.write("".join("f %d %d %d %d\n" % q for q in f))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/shadow"))
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    d = tempfile.mkdtemp()
    s, b, p, o = (os.path.join(d, n) for n in ("s.obj", "b.obj", "p.obj", "o.obj"))

    def volume(op, x, y):
        r = subprocess.run([args.bin, "csg", op, x, y, "-o", o, "--stats"],
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(r.stderr.strip().splitlines()[-1][:200])
        return float(re.search(r"volume:\s+(\S+) \(exact", r.stdout).group(1))

    rng = random.Random(args.seed)
    failed = 0
    for case in range(args.cases):
        n = rng.choice([800, 1500, 2500, 4000])
        va, tris = uv_sphere(n)
        write_obj(s, va, tris)
        c = [rng.uniform(-0.5, 0.5) for _ in range(3)]
        lo = [c[0] + rng.uniform(-0.2, 0.3), -2, -2] if rng.random() < 0.5 else [c[0], c[1], -2]
        box(b, lo, [2, 2, 2])
        op = rng.choice(["difference", "intersection"])
        try:
            subprocess.run([args.bin, "csg", op, s, b, "-o", p, "-q"], check=True,
                           capture_output=True)
            vs = volume("intersection", s, s)
            vp = volume("intersection", p, p)
            vu = volume("union", s, p)
            vd = volume("difference", p, s)
            vi = volume("intersection", s, p)
        except (RuntimeError, subprocess.CalledProcessError) as e:
            failed += 1
            print(f"case {case}: {n} triangles, {op} with a box from {lo}: {e}")
            continue
        if abs(vu - (vs + vd)) > 1e-12 * vs or abs(vi - (vp - vd)) > 1e-9 * vs:
            failed += 1
            print(f"case {case}: volumes {vu} != {vs} + {vd} or {vi} != {vp} - {vd}")
    print(f"{args.cases - failed} of {args.cases} cases hold")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
