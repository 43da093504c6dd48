#!/usr/bin/env python3
"""The Python package's figures (docs/python.md), outside CI.

1. Union of two ~100k-triangle UV spheres (the inputs of
   scripts/manifold_compare.py: a copy rotated 5 degrees and shifted) from
   numpy arrays, in paired rounds: `bs.union` with the arrays converted in
   and out, manifold3d's Python call (`Manifold(Mesh(...))` for both, `+`,
   `to_mesh()`), and the Rust library's `bsp_shadows::union` on the same
   meshes in memory (`shadows/examples/union_time.rs`, its own timing).
2. The package's import time.
3. A year-long sun study (the 1st of each month, 15-minute steps) of a
   built-in scene: one process (all CPUs) against a Dask LocalCluster of
   2 workers x 1 thread, with each task's time, so the time on 100 workers
   can be estimated from the measured costs; with --tiles N, the scene cut
   into N x N tiles (a task a run and tile), each task's peak memory in a
   process of its own.

    python3 -m venv /tmp/pyv && /tmp/pyv/bin/pip install './python[test]' manifold3d
    cargo build --release -p bsp-shadows --example union_time
    /tmp/pyv/bin/python scripts/python_bench.py [--rounds 5] [--scene bunny-99k] [--skip-sun]
        [--skip-booleans] [--tiles N]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from manifold_compare import SHIFT, rotate, uv_sphere, write_obj  # noqa: E402

import bsp_shadows as bs  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def spheres(n):
    va, tris = uv_sphere(n)
    vb = rotate(va) + np.array(SHIFT)
    return np.ascontiguousarray(va), np.ascontiguousarray(vb), np.ascontiguousarray(tris)


def ours(va, vb, tris):
    t = time.perf_counter()
    u = bs.Mesh(va, tris) | bs.Mesh(vb, tris)
    v, f = u.vertices, u.faces
    return time.perf_counter() - t, len(f)


def manifold(va, vb, tris):
    from manifold3d import Manifold, Mesh

    t = time.perf_counter()
    a = Manifold(Mesh(vert_properties=va.astype(np.float32), tri_verts=tris.astype(np.uint32)))
    b = Manifold(Mesh(vert_properties=vb.astype(np.float32), tri_verts=tris.astype(np.uint32)))
    m = (a + b).to_mesh()
    return time.perf_counter() - t, len(m.tri_verts)


def booleans(args):
    va, vb, tris = spheres(args.triangles)
    print(f"union of two UV spheres of {len(tris)} triangles, {args.rounds} paired rounds")
    ours(va, vb, tris), manifold(va, vb, tris)  # warm both
    ratios_m, ratios_r, t_ours, t_man, t_rust = [], [], [], [], []
    with tempfile.TemporaryDirectory() as d:
        pa, pb = os.path.join(d, "a.obj"), os.path.join(d, "b.obj")
        write_obj(pa, va, tris)
        write_obj(pb, vb, tris)
        for _ in range(args.rounds):
            # one round: ours, manifold3d, the Rust library (its own timing
            # of its second union, in a process of its own), back to back
            (a, fa), (m, fm) = ours(va, vb, tris), manifold(va, vb, tris)
            out = subprocess.run([args.example, pa, pb, "2"], check=True, capture_output=True, text=True)
            r = float(out.stdout.split()[-2])  # (the second: warm, as ours)
            t_ours.append(a)
            t_man.append(m)
            t_rust.append(r)
            ratios_m.append(a / m)
            ratios_r.append(a / r)
    mo, mm, mr = (statistics.median(x) for x in (t_ours, t_man, t_rust))
    print(f"  bs.union (arrays in and out): median {mo:.3f} s, {fa} triangles")
    print(f"  manifold3d (Manifold(Mesh) x2, +, to_mesh): median {mm:.3f} s, {fm} triangles")
    print(f"  Rust bsp_shadows::union (meshes in memory): median {mr:.3f} s")
    print(f"  ratio bs/manifold3d: median of rounds {statistics.median(ratios_m):.2f} "
          f"(range {min(ratios_m):.2f}-{max(ratios_m):.2f})")
    print(f"  overhead of Python over Rust: median of rounds {100 * (statistics.median(ratios_r) - 1):+.1f}% "
          f"(range {100 * (min(ratios_r) - 1):+.1f}% to {100 * (max(ratios_r) - 1):+.1f}%)")


def import_time():
    code = "import time; t = time.perf_counter(); import bsp_shadows; print(time.perf_counter() - t)"
    runs = [float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                 text=True).stdout) for _ in range(5)]
    print(f"import bsp_shadows: median {statistics.median(runs):.3f} s of 5 (with numpy)")


def timed_run(mesh, suns, step, tile=None):
    bs.set_threads(1)
    t = time.perf_counter()
    r = bs._native._hours_run(mesh, suns, step, False, tile)
    return time.perf_counter() - t, r


def fresh_task(scene_name, suns, step, tile):
    """One task in a process of its own: its time and the process's peak
    memory (MiB; the scene, the package and the task)."""
    import resource

    scene = bs.Mesh.scene(scene_name)
    t, _ = timed_run(scene, suns, step, tile)
    return t, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def sun_study(args):
    from distributed import Client, LocalCluster

    import bsp_shadows.distributed as bsd

    scene = bs.Mesh.scene(args.scene)
    dates = [f"2026-{m:02d}-01" for m in range(1, 13)]
    # each face's exact mean hours; the extremes' overlay grows quadratically
    # in the suns on the ground under the bunny (see bs.sun_hours)
    up = "y" if args.scene.startswith("bunny") else "z"  # (the scans stand with y up)
    study = dict(lat=51.5, lon=-0.1, dates=dates, step_minutes=15, extremes=False, up=up,
                 tiles=args.tiles)
    suns = bs.study_suns(51.5, -0.1, dates, 15, up=up)
    runs = bsd.runs_of(suns)
    tasks = bsd.tasks_of(suns, args.tiles)
    print(f"sun study: {args.scene} ({len(scene.faces)} faces), 12 days, 15-minute steps: "
          f"{len(suns)} suns in {len(runs)} runs, {args.tiles} x {args.tiles} tiles: "
          f"{len(tasks)} tasks")
    # one task at a time in a fresh process: its time and peak memory
    import concurrent.futures
    import multiprocessing

    spawn = multiprocessing.get_context("spawn")
    for task in tasks[:4]:
        with concurrent.futures.ProcessPoolExecutor(1, mp_context=spawn) as pool:
            t, peak = pool.submit(fresh_task, args.scene, *task[:1], 0.25, task[1]).result()
        print(f"  task (run of {len(task[0])} suns, tile {task[1]}), fresh process, 1 thread: "
              f"{t:.1f} s, peak {peak:.0f} MiB")
    t = time.perf_counter()
    single = bs.sun_hours(scene, **study)
    t_single = time.perf_counter() - t
    print(f"  one process ({bs.get_threads()} threads): {t_single:.1f} s")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=40) as cluster, Client(cluster) as client:
        t = time.perf_counter()
        h = bsd.sun_hours(scene, client, threads_per_task=1, **study)
        t_dask = time.perf_counter() - t
        # each task's own cost, one at a time on a worker (for the estimate)
        mesh = client.scatter(scene, broadcast=True)
        costs = client.gather([client.submit(lambda m, s, c: timed_run(m, s, 0.25, c)[0], mesh, r,
                                             c, pure=False) for r, c in tasks[:2]])
    same = (h.per_face == single.per_face).all() and (h.area == single.area).all()
    print(f"  Dask LocalCluster 2 workers x 1 thread: {t_dask:.1f} s "
          f"(ratio to one process {t_dask / t_single:.2f}); the same bits: {same}")
    parts = [bs._native._hours_run(scene, r, 0.25, False, c) for r, c in tasks[:2]]
    t = time.perf_counter()
    bs._native._fold_runs(scene, parts, suns[: sum(len(r) for r, _ in tasks[:2])], 0.25)
    fold2 = time.perf_counter() - t
    task = statistics.mean(costs)
    fold = fold2 / 2 * len(tasks)
    est = task * -(-len(tasks) // 100) + fold
    print(f"  a task (one run of up to {bs.MAX_SUNS_A_RUN} suns, 1 thread): {task:.1f} s; "
          f"folding on the driver: {fold2 / 2:.2f} s a task")
    print(f"  100 workers: at most {len(tasks)} tasks run at once, so about {est:.1f} s "
          f"(a task's time plus the fold of {len(tasks)} tasks), before scheduling overheads")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--triangles", type=int, default=100_000)
    p.add_argument("--scene", default="bunny-99k")
    p.add_argument("--skip-sun", action="store_true")
    p.add_argument("--skip-booleans", action="store_true")
    p.add_argument("--tiles", type=int, default=1, help="the sun study cut into N x N tiles")
    p.add_argument("--example", default=os.path.join(ROOT, "target", "release", "examples", "union_time"))
    args = p.parse_args()
    print(f"load: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} CPUs; threads {bs.get_threads()}")
    if not args.skip_booleans:
        booleans(args)
    import_time()
    if not args.skip_sun:
        sun_study(args)


if __name__ == "__main__":
    main()
