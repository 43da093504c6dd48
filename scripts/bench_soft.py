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
the walls above it too). At most 64 lights fit one run, so N stops at 64.

    python3 scripts/bench_soft.py [--runs 5]
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


def area_below(ring, z):
    """The area of a planar ring's part with z <= `z` (Sutherland-Hodgman
    and Newell: right for non-convex rings too)."""
    clipped = []
    for i, a in enumerate(ring):
        b = ring[(i + 1) % len(ring)]
        if a[2] <= z:
            clipped.append(a)
        if (a[2] <= z) != (b[2] <= z):
            t = (z - a[2]) / (b[2] - a[2])
            clipped.append([a[k] + t * (b[k] - a[k]) for k in range(3)])
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(clipped):
        b = clipped[(i + 1) % len(clipped)]
        n[0] += (a[1] - b[1]) * (a[2] + b[2])
        n[1] += (a[2] - b[2]) * (a[0] + b[0])
        n[2] += (a[0] - b[0]) * (a[1] + b[1])
    return 0.5 * sum(c * c for c in n) ** 0.5


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


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--runs", type=int, default=5)
    runs = p.parse_args().runs
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
        args = []
        for i in range(k):
            for j in range(k):
                x = x0 + (i + 0.5) * 2 * HALF / k
                y = y0 + (j + 0.5) * 2 * HALF / k
                args += ["--light", f"{x},{y},{Z}"]
        t = timed(args, out, runs)
        tot, l, u = areas(json.load(open(out)))
        assert abs(tot - total) < 1e-6 * total, (tot, total)
        print(f"| {k * k} point lights | {t:.3f} | {100 * (l - lit) / total:+.2f} % | "
              f"{100 * (u - umbra) / total:+.2f} % |")


if __name__ == "__main__":
    main()
