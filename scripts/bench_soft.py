#!/usr/bin/env python3
"""Exact soft shadows against sampled area lights, on the room.

The area light (a 0.4 x 0.4 square facing down at the room's key light)
is computed exactly (`--area-light`) and approximated by N point lights
on a regular sqrt(N) x sqrt(N) lattice of cell centres (N exact point
lights: a fragment lit by all of them counts as lit, by none as umbra).
For each, the median wall time of a few runs of the release binary (the
README's first command builds it) and the error of the lit and umbra
areas against the exact ones, in percent of the room's area below the
light's plane (the area light shines down only; the point lights light
the walls above it too).

At most 64 lights fit one run. N = 256 (a 16 x 16 lattice) is measured
as four runs of 64 (the four interleaved 8 x 8 sub-lattices): a point is
lit by all 256 where it is lit by all of each run's 64, so the area lit
by all is that of the intersection, face by face, of the four runs'
fragments lit by all (and so for the umbra), found with `shapely` in
each face's plane. Its time is the four runs' together. The same
intersection of four runs of 16 is checked against the one run of 64
(N = 64 both ways must agree to rounding).

    python3 scripts/bench_soft.py [--runs 5] [--no-256]

(N = 256 needs `pip install shapely`; without it that row is skipped.)
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "shadow")
CX, CY, Z, HALF = 0.9, 0.3, 2.45, 0.2


def run(args, out):
    cmd = [BIN, "shadows", "--scene", "room", "-q", "-o", out] + args
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def timed(args, out, runs):
    run(args, out)  # warm-up
    return statistics.median(run(args, out) for _ in range(runs))


def clip_below(ring, z):
    """A planar ring's part with z <= `z` (Sutherland-Hodgman: right for
    non-convex rings too, whose clipped part may then run along z = `z`
    more than once)."""
    clipped = []
    for i, a in enumerate(ring):
        b = ring[(i + 1) % len(ring)]
        if a[2] <= z:
            clipped.append(a)
        if (a[2] <= z) != (b[2] <= z):
            t = (z - a[2]) / (b[2] - a[2])
            clipped.append([a[k] + t * (b[k] - a[k]) for k in range(3)])
    return clipped


def newell(ring):
    """Twice a planar ring's vector area (Newell's normal)."""
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(ring):
        b = ring[(i + 1) % len(ring)]
        n[0] += (a[1] - b[1]) * (a[2] + b[2])
        n[1] += (a[2] - b[2]) * (a[0] + b[0])
        n[2] += (a[0] - b[0]) * (a[1] + b[1])
    return n


def area_below(ring, z):
    """The area of a planar ring's part with z <= `z`."""
    return 0.5 * sum(c * c for c in newell(clip_below(ring, z))) ** 0.5


def areas(doc):
    """The area below the light's plane: in all, lit by every light, by none."""
    total = lit = umbra = 0.0
    for f in doc["fragments"]:
        a = area_below(f["vertices"], Z) - sum(area_below(h, Z) for h in f.get("holes", []))
        total += a
        if all(f["lit"]):
            lit += a
        elif all(f["umbra"]):
            umbra += a
    return total, lit, umbra


def lattice(k, x0, y0, step=1, offset=(0, 0)):
    """`--light` arguments of a k x k lattice of cell centres over the
    light, every `step`-th cell from `offset` in each direction."""
    args = []
    for i in range(offset[0], k, step):
        for j in range(offset[1], k, step):
            x = x0 + (i + 0.5) * 2 * HALF / k
            y = y0 + (j + 0.5) * 2 * HALF / k
            args += ["--light", f"{x},{y},{Z}"]
    return args


def face_frame(ring):
    """The axis a face's plane is projected along (its normal's largest
    component) and the factor from projected area to true area."""
    n = newell(ring)
    norm = sum(c * c for c in n) ** 0.5
    # (a face at 45 degrees has two equal components: rounded, the first
    # is taken in every run, so that the runs' projections agree)
    axis = max(range(3), key=lambda k: (round(abs(n[k]) / norm, 9), -k))
    return axis, norm / abs(n[axis])


def face_regions(doc):
    """Per face: its area factor, and the unions of its fragments lit by
    every light and hidden from every light, below the light's plane, as
    `shapely` geometry in the face's projected plane."""
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    faces = {}
    for f in doc["fragments"]:
        faces.setdefault(f["face"], []).append(f)
    out = {}
    for face, frags in faces.items():
        axis, scale = face_frame(frags[0]["vertices"])
        keep = [k for k in range(3) if k != axis]

        def flat(ring):
            # (clipped in space, where z is always a coordinate)
            ring = clip_below(ring, Z)
            if len(ring) < 3:
                return Polygon()
            return Polygon([(p[keep[0]], p[keep[1]]) for p in ring]).buffer(0)

        lit, umbra = [], []
        for f in frags:
            g = flat(f["vertices"])
            for h in f.get("holes", []):
                g = g.difference(flat(h))
            if all(f["lit"]):
                lit.append(g)
            elif all(f["umbra"]):
                umbra.append(g)
        out[face] = (scale, unary_union(lit), unary_union(umbra))
    return out


def joint_areas(docs):
    """The areas lit by every light of every run and hidden from every
    light of every run: the intersection, face by face, of the runs'
    regions (`face_regions`)."""
    regions = [face_regions(d) for d in docs]
    lit = umbra = 0.0
    for face in set().union(*regions):
        per = [r.get(face) for r in regions]
        if any(p is None for p in per):
            continue
        scale = per[0][0]
        a, b = per[0][1], per[0][2]
        for p in per[1:]:
            a, b = a.intersection(p[1]), b.intersection(p[2])
        lit += scale * a.area
        umbra += scale * b.area
    return lit, umbra


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--no-256", action="store_true", help="skip N = 256 (four runs of 64)")
    opts = p.parse_args()
    runs = opts.runs
    if not os.path.exists(BIN):
        sys.exit(f"build first: cargo build --release -p shadow-cli ({BIN})")
    d = tempfile.mkdtemp()
    out = os.path.join(d, "soft.json")
    x0, x1, y0, y1 = CX - HALF, CX + HALF, CY - HALF, CY + HALF
    square = f"{x0},{y0},{Z};{x0},{y1},{Z};{x1},{y1},{Z};{x1},{y0},{Z}"
    t_exact = timed(["--area-light", square], out, runs)
    total, lit, umbra = areas(json.load(open(out)))
    print(f"# room, 0.4 x 0.4 light at {CX},{CY},{Z}; median of {runs} runs; load "
          f"{os.getloadavg()[0]:.2f}")
    print("| light | time (s) | lit area error | umbra area error |")
    print("|---|---|---|---|")
    print(f"| exact (`--area-light`) | {t_exact:.3f} | 0 | 0 |")
    for k in (2, 4, 6, 8):
        t = timed(lattice(k, x0, y0), out, runs)
        tot, l, u = areas(json.load(open(out)))
        assert abs(tot - total) < 1e-6 * total, (tot, total)
        print(f"| {k * k} point lights | {t:.3f} | {100 * (l - lit) / total:+.2f} % | "
              f"{100 * (u - umbra) / total:+.2f} % |")
        if k == 8:
            lit64, umbra64 = l, u
    if opts.no_256:
        return
    try:
        import shapely  # noqa: F401
    except ImportError:
        print("(N = 256 skipped: pip install shapely)")
        return
    subs = [(a, b) for a in range(2) for b in range(2)]

    def four(k):
        t, docs = 0.0, []
        for s in subs:
            t += timed(lattice(k, x0, y0, 2, s), out, runs)
            docs.append(json.load(open(out)))
        return t, joint_areas(docs)

    # the four-run intersection checked where one run can do it too
    _, (l, u) = four(8)
    assert abs(l - lit64) < 1e-9 * total and abs(u - umbra64) < 1e-9 * total, (
        l, lit64, u, umbra64)
    t, (l, u) = four(16)
    print(f"| 256 point lights (four runs of 64) | {t:.3f} | {100 * (l - lit) / total:+.2f} % | "
          f"{100 * (u - umbra) / total:+.2f} % |")


if __name__ == "__main__":
    main()
