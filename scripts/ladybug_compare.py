#!/usr/bin/env python3
"""Exact sun-hours against a Ladybug-style ray study, on the same scene and suns.

Outside CI (it needs the package registry). Ladybug's "Direct Sun Hours"
puts one sensor on each face (its centre, moved off the face along its
normal; here by 10⁻⁶ of the scene's size, the scene moved to the origin
first so that Embree's float32 keeps that offset) and casts one ray from every sensor toward every sun; it counts
the suns a sensor sees. Here that is done with Embree (the ``embreex``
package: its BVH over the scene's triangles, then the shadow rays), with
the same suns as ours (``bsp_shadows.study_suns``: the middles of the
day's ``--step``-minute intervals, above the horizon). Ours is ``shadow
sunhours --no-extremes`` end to end (load, snap, every sun's exact lit
area of every face, CSV written), the binary given. Both run ``--runs``
times in turn; the medians and their ratio are printed.

Then the accuracy, on ``--sensors`` faces picked at random (a fixed seed),
a sensor at each one's centre moved off it by 10⁻⁶ of the scene's size:

- each tool's hours at the sensors against ``--exact-time``'s (no time
  sampling; ``bsp_shadows.sensor_intervals``): the rays at the suns, and
  the exact engine at the same suns (``SunHours.per_sensor``). Both are
  sampled in time, so both carry the step's error; the model of the sun
  also differs by refraction, which ``--exact-time`` leaves out (a few
  minutes a day);
- how far one sensor's hours are from its face's mean (the exact per-face
  hours): what a one-point-per-face study misses on faces that a shadow
  edge crosses.

    python3 -m venv /tmp/emb && /tmp/emb/bin/pip install embreex numpy ./python
    cargo build --release -p shadow-cli
    /tmp/emb/bin/python scripts/ladybug_compare.py --scene bunny-11k --runs 3
    /tmp/emb/bin/python scripts/ladybug_compare.py --mesh city.json --lat 52.01 --lon 4.36
"""

import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def triangles_and_faces(mesh):
    """The faces fanned into triangles, ``(t, 3, 3)``, and each triangle's
    face."""
    v = mesh.vertices
    tris, owner = [], []
    for i, f in enumerate(mesh.faces):
        f = np.asarray(f)
        for k in range(1, len(f) - 1):
            tris.append([f[0], f[k], f[k + 1]])
            owner.append(i)
    return v[np.array(tris)], np.array(owner)


def face_sensors(tris, owner, faces, size):
    """One sensor per face: its area-weighted centre, moved off it along
    its normal by 10⁻⁶ of ``size``; and the normals."""
    cross = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    area = np.linalg.norm(cross, axis=1) / 2
    centre = tris.mean(axis=1)
    a = np.zeros(faces)
    c = np.zeros((faces, 3))
    n = np.zeros((faces, 3))
    np.add.at(a, owner, area)
    np.add.at(c, owner, centre * area[:, None])
    np.add.at(n, owner, cross)
    c /= np.maximum(a, 1e-300)[:, None]
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]
    return c + n * (1e-6 * size), n


def ray_pass(tris, pts, normal, suns, step_hours):
    """Ladybug's study with Embree: hours per sensor, and the seconds."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rtcs

    start = time.perf_counter()
    scene = rtcs.EmbreeScene()
    mc.TriangleMesh(scene=scene, vertices=tris.astype(np.float32))
    seen = np.zeros(len(pts))
    origin = pts.astype(np.float32)
    for d in suns:
        d = d / np.linalg.norm(d)
        dirs = np.broadcast_to(d, pts.shape).astype(np.float32)
        hit = scene.run(origin, dirs, query="OCCLUDED")
        seen += (normal @ d > 0) & (hit == -1)
    return seen * step_hours, time.perf_counter() - start


def ours_pass(binary, source, site, out):
    start = time.perf_counter()
    subprocess.run([binary, "sunhours", *source, *site, "--no-extremes", "-o", out, "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    took = time.perf_counter() - start
    with open(out) as f:
        hours = np.array([float(r["sun_hours"]) for r in csv.DictReader(f)])
    return hours, took


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="bunny-11k", help="a built-in scene")
    ap.add_argument("--mesh", help="a mesh file instead (OBJ, STL, CityJSON)")
    ap.add_argument("--lat", type=float, default=51.5)
    ap.add_argument("--lon", type=float, default=-0.12)
    ap.add_argument("--date", default="2026-03-21")
    ap.add_argument("--step", type=float, default=10.0, help="minutes between suns")
    ap.add_argument("--sensors", type=int, default=200)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/shadow"))
    args = ap.parse_args()
    import bsp_shadows as bs

    mesh = bs.read_mesh(args.mesh) if args.mesh else bs.Mesh.scene(args.scene)
    source = [args.mesh] if args.mesh else ["--scene", args.scene]
    site = ["--lat", str(args.lat), "--lon", str(args.lon), "--date", args.date,
            "--step", str(args.step)]
    tris, owner = triangles_and_faces(mesh)
    faces = len(mesh.faces)
    size = np.ptp(tris.reshape(-1, 3), axis=0).max()
    centre = (tris.reshape(-1, 3).min(0) + tris.reshape(-1, 3).max(0)) / 2
    pts, normal = face_sensors(tris, owner, faces, size)
    suns = bs.study_suns(args.lat, args.lon, [args.date], args.step)
    step_hours = args.step / 60
    mine, theirs = [], []
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "hours.csv")
        for _ in range(args.runs):
            exact_faces, t = ours_pass(args.bin, source, site, out)
            mine.append(t)
            # (about the origin: Embree's float32 would lose a city's
            # national-grid coordinates, and the sensors' offsets with them)
            rays, t = ray_pass(tris - centre, pts - centre, normal, suns, step_hours)
            theirs.append(t)
    a, b = statistics.median(mine), statistics.median(theirs)
    print(f"{args.mesh or args.scene}: {faces} faces ({len(tris)} triangles), {len(suns)} suns "
          f"on {args.date} every {args.step:g} min at {args.lat}, {args.lon}")
    print(f"ours (shadow sunhours --no-extremes, exact per face, end to end): median {a:.3f} s "
          f"of {args.runs}: {[round(x, 3) for x in sorted(mine)]}")
    print(f"rays (Embree BVH + one ray per face and sun): median {b:.3f} s: "
          f"{[round(x, 3) for x in sorted(theirs)]}")
    print(f"ratio ours/rays: {a / b:.2f}")

    rng = np.random.default_rng(1)
    pick = rng.choice(faces, size=min(args.sensors, faces), replace=False)
    at = pts[pick]
    start = time.perf_counter()
    on = bs.sensor_intervals(mesh, at, lat=args.lat, lon=args.lon, dates=[args.date])
    t_exact = time.perf_counter() - start
    exact = np.array([sum((iv[:, 1] - iv[:, 0]).sum() for iv in days) for days in on])
    study = bs.sun_hours(mesh, lat=args.lat, lon=args.lon, dates=[args.date],
                         step_minutes=args.step, extremes=False)
    sampled = study.per_sensor(at)
    err = lambda h: (np.abs(h - exact).mean(), np.abs(h - exact).max())
    print(f"at {len(pick)} sensors, against --exact-time ({t_exact:.2f} s): "
          "mean and largest error, hours")
    print("  rays at the suns:          %.4f  %.4f" % err(rays[pick]))
    print("  exact engine at the suns:  %.4f  %.4f" % err(sampled))
    gap = np.abs(rays[pick] - exact_faces[pick])
    print(f"one sensor against its face's exact mean: mean {gap.mean():.4f} h, "
          f"largest {gap.max():.4f} h, faces off by over half an hour {(gap > 0.5).sum()}")


if __name__ == "__main__":
    sys.exit(main())
