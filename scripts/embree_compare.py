#!/usr/bin/env python3
"""Exact shadows against Embree's shadow rays, on the same scene and light.

Outside CI (it needs the package registry). The peer is Embree through
the ``embreex`` package: its BVH built over the scene's triangles, then
one shadow ray toward the point light from each of N points spread over
the faces by area (``--rays``, default 1M; a fixed seed). Ours is
``shadow shadows`` end to end (load, snap, shadows, JSON written), the
binary given. Both run ``--runs`` times in turn; the medians and their
ratio are printed, with the lit share each finds: the exact one (lit area
over total area) and Embree's (the share of its points that see the
light), which agree to within the sampling's error.

    python3 -m venv /tmp/emb && /tmp/emb/bin/pip install embreex numpy ./python
    cargo build --release -p shadow-cli
    /tmp/emb/bin/python scripts/embree_compare.py --scene bunny-99k --runs 3

``--image 1920x1080`` compares images instead: ``shadow render --method
exact`` end to end (load, snap, shadows, PNG written) against Embree
ray tracing the same view (BVH, a primary ray through each pixel, a
shadow ray from each hit toward the light), with the share of the visible
pixels each finds lit.

The scene is a built-in one (``bsp_shadows.Mesh.scene``: its polygons
fanned into triangles for Embree), or with ``--file PATH`` a mesh file
(OBJ or STL, read by ``bsp_shadows.Mesh.read``, and by ``shadow shadows
PATH``: the load is in our time, as a new user's run has it); the light defaults to the bunny scenes'
own light (above and in front of the bunny); ``--light X,Y,Z`` and
``--sun X,Y,Z`` (each repeatable) give others, one Embree pass each.
A sample point is moved toward the light by 10⁻⁶ of the scene's size so
that its ray does not hit its own face; a point on a face turned away from
the light counts as shadowed, as the exact engine counts that face.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def triangles_of(mesh):
    """The faces fanned into triangles, ``(t, 3, 3)`` float64."""
    v = mesh.vertices
    faces = mesh.faces
    if isinstance(faces, np.ndarray) and faces.shape[1] == 3:
        return v[faces]
    tris = []
    for f in faces:
        f = np.asarray(f)
        for k in range(1, len(f) - 1):
            tris.append([f[0], f[k], f[k + 1]])
    return v[np.array(tris)]


def default_light(tris):
    """The bunny scenes' light: above and in front of the bounds' centre."""
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    c, half = (lo + hi) / 2, (hi - lo).max() / 2
    return c + np.array([0.4, 1.6, 0.6]) * half


def samples(tris, n, seed=1):
    """`n` points spread over the triangles by area, and each one's unit
    normal."""
    rng = np.random.default_rng(seed)
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    cross = np.cross(e1, e2)
    area = np.linalg.norm(cross, axis=1) / 2
    pick = rng.choice(len(tris), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    pts = tris[pick, 0] + u[:, None] * e1[pick] + v[:, None] * e2[pick]
    normal = cross[pick] / np.maximum(np.linalg.norm(cross[pick], axis=1), 1e-300)[:, None]
    return pts, normal


def embree_pass(tris, pts, normal, lights):
    """One Embree run: the BVH built, then a shadow ray per point and
    light (`lights`: ("point", p) or ("sun", d)). Each light's share of
    points lit, and the seconds it took."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rtcs

    size = np.ptp(tris.reshape(-1, 3), axis=0).max()
    start = time.perf_counter()
    scene = rtcs.EmbreeScene()
    mc.TriangleMesh(scene=scene, vertices=tris.astype(np.float32))
    shares = []
    for kind, x in lights:
        if kind == "point":
            to_light = x - pts
            dist = np.linalg.norm(to_light, axis=1)
            d = to_light / dist[:, None]
            far = dist * (1 - 1e-6)
        else:
            d = np.broadcast_to(x / np.linalg.norm(x), pts.shape)
            far = np.full(len(pts), np.inf)
        origin = pts + d * (1e-6 * size)
        hit = scene.run(origin.astype(np.float32), d.astype(np.float32),
                        query="OCCLUDED", dists=far.astype(np.float32))
        facing = (normal * d).sum(1) > 0
        shares.append((facing & (hit == -1)).mean())
    return shares, time.perf_counter() - start


def ours_pass(binary, scene, lights, out):
    """``scene``: the arguments naming the scene (``--scene NAME`` or a
    file's path)."""
    flags = []
    for kind, x in lights:
        flags += ["--light" if kind == "point" else "--sun", ",".join(repr(float(c)) for c in x)]
    start = time.perf_counter()
    subprocess.run([binary, "shadows", *scene, *flags, "-o", out, "--quiet"],
                   check=True, stdout=subprocess.DEVNULL)
    took = time.perf_counter() - start
    summary = json.load(open(out))["summary"]
    return [lit / summary["area"] for lit in summary["lit_area"]], took


def view_of(tris):
    """A view of the scene: the eye in front, right and above the bounds'
    centre, looking at it, `y` up (the bunny scenes' up)."""
    lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
    c, half = (lo + hi) / 2, (hi - lo).max() / 2
    return c + np.array([1.2, 0.9, 2.2]) * half, c, np.array([0.0, 1.0, 0.0]), 50.0


def embree_image(tris, view, size, light):
    """Embree ray tracing an image: the BVH built, a primary ray through
    each pixel's centre (pinhole, vertical field of view), and a shadow
    ray toward the point light from each hit, lit where the hit face is
    turned toward the light (as the exact engine counts it). The share of
    the visible pixels lit, and the seconds it took."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rtcs

    eye, target, up, fov = view
    w, h = size
    start = time.perf_counter()
    scene = rtcs.EmbreeScene()
    mc.TriangleMesh(scene=scene, vertices=tris.astype(np.float32))
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    t = np.tan(np.radians(fov) / 2)
    xs = (2 * (np.arange(w) + 0.5) / w - 1) * t * w / h
    ys = (1 - 2 * (np.arange(h) + 0.5) / h) * t
    d = fwd + xs[None, :, None] * right + ys[:, None, None] * upv
    d = (d / np.linalg.norm(d, axis=2)[..., None]).reshape(-1, 3).astype(np.float32)
    o = np.broadcast_to(eye.astype(np.float32), d.shape)
    res = scene.run(o, d, output=1)
    prim, dist = res["geomID"] >= 0, res["tfar"]
    hit = np.nonzero(prim)[0]
    pts = eye + d[hit].astype(np.float64) * dist[hit, None]
    tri = tris[res["primID"][hit]]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    # the side of the face the eye sees
    n *= np.where((n * d[hit]).sum(1) < 0, 1.0, -1.0)[:, None]
    to_light = light - pts
    dist_l = np.linalg.norm(to_light, axis=1)
    dl = to_light / dist_l[:, None]
    size_s = np.ptp(tris.reshape(-1, 3), axis=0).max()
    origin = pts + dl * (1e-6 * size_s)
    blocked = scene.run(origin.astype(np.float32), dl.astype(np.float32),
                        query="OCCLUDED", dists=(dist_l * (1 - 1e-6)).astype(np.float32))
    lit = ((n * dl).sum(1) > 0) & (blocked == -1)
    return lit.mean(), time.perf_counter() - start


def ours_image(binary, scene, view, size, light, out):
    """`shadow render --method exact` of the same view: the share of the
    visible pixels lit (from its report), and the seconds it took."""
    eye, target, up, fov = view
    flag = lambda x: ",".join(repr(float(c)) for c in x)
    start = time.perf_counter()
    said = subprocess.run(
        [binary, "render", *scene, "--method", "exact", "--size", f"{size[0]}x{size[1]}",
         "--eye", flag(eye), "--target", flag(target), "--up", flag(up), "--fov", str(fov),
         "--light", flag(light), "-o", out],
        check=True, capture_output=True, text=True).stdout
    took = time.perf_counter() - start
    share = float(said.split("% of the visible pixels lit")[0].split()[-1]) / 100
    return share, took


def image_main(args, tris, lights, scene, name):
    size = tuple(int(x) for x in args.image.split("x"))
    (kind, light), = lights
    if kind != "point":
        raise SystemExit("--image takes one point light")
    view = view_of(tris)
    mine, theirs = [], []
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "image.png")
        for _ in range(args.runs):
            lit_exact, t = ours_image(args.bin, scene, view, size, light, out)
            mine.append(t)
            lit_rays, t = embree_image(tris, view, size, light)
            theirs.append(t)
    a, b = statistics.median(mine), statistics.median(theirs)
    print(f"scene {name}: {len(tris)} triangles; {size[0]}x{size[1]}, eye "
          f"{','.join(f'{c:.4g}' for c in view[0])}")
    print(f"ours (shadow render --method exact, end to end): median {a:.3f} s of {args.runs}: {sorted(mine)}")
    print(f"Embree (BVH + a primary ray a pixel + a shadow ray a hit): median {b:.3f} s: {sorted(theirs)}")
    print(f"ratio ours/Embree: {a / b:.2f}")
    print(f"visible pixels lit: exact {lit_exact:.4f}, Embree {lit_rays:.4f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="bunny-99k")
    ap.add_argument("--file", metavar="PATH", help="a mesh file (OBJ or STL) instead of --scene")
    ap.add_argument("--light", action="append", default=[],
                    help="a point light X,Y,Z, repeatable (default, with no --sun: the bunny scenes' light)")
    ap.add_argument("--sun", action="append", default=[], help="a sun's direction X,Y,Z, repeatable")
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/shadow"))
    ap.add_argument("--image", metavar="WxH",
                    help="compare images instead: `shadow render --method exact` against Embree "
                         "ray tracing the same view (one point light)")
    args = ap.parse_args()
    import bsp_shadows as bs

    mesh = bs.Mesh.read(args.file) if args.file else bs.Mesh.scene(args.scene)
    scene = [args.file] if args.file else ["--scene", args.scene]
    name = args.file or args.scene
    tris = triangles_of(mesh)
    vec = lambda t: np.array([float(x) for x in t.split(",")])
    lights = [("point", vec(t)) for t in args.light] + [("sun", vec(t)) for t in args.sun]
    if not lights:
        lights = [("point", default_light(tris))]
    if args.image:
        return image_main(args, tris, lights, scene, name)
    pts, normal = samples(tris, args.rays)
    mine, theirs = [], []
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "shadows.json")
        for _ in range(args.runs):
            lit_exact, t = ours_pass(args.bin, scene, lights, out)
            mine.append(t)
            lit_rays, t = embree_pass(tris, pts, normal, lights)
            theirs.append(t)
    a, b = statistics.median(mine), statistics.median(theirs)
    said = "; ".join(f"{k} {','.join(f'{c:.6g}' for c in x)}" for k, x in lights)
    print(f"scene {name}: {len(tris)} triangles; lights: {said}")
    print(f"ours (shadow shadows, end to end): median {a:.3f} s of {args.runs}: {sorted(mine)}")
    print(f"Embree (BVH + {args.rays} shadow rays a light): median {b:.3f} s: {sorted(theirs)}")
    print(f"ratio ours/Embree: {a / b:.2f}")
    for i, (e, r) in enumerate(zip(lit_exact, lit_rays)):
        print(f"light {i} lit share: exact {e:.5f}, Embree's points {r:.5f} "
              f"(sampling error about {1 / np.sqrt(args.rays):.1e})")


if __name__ == "__main__":
    sys.exit(main())
