"""Sun studies on an existing engine: Dask or Ray.

A study is split into runs of at most ``MAX_SUNS_A_RUN`` suns, the same
runs the single-process ``bsp_shadows.sun_hours`` makes; each run is a task
that returns its partial sums (exact per sun) as bytes, and the driver folds
them in the runs' order. The result is therefore the same, bit for bit, as
one process's.

    >>> from dask.distributed import Client
    >>> client = Client()                    # or Client("tcp://scheduler:8786")
    >>> h = bs.distributed.sun_hours(scene, client, lat=51.5, lon=0, dates=days)

    >>> import ray; ray.init()
    >>> h = bs.distributed.sun_hours(scene, "ray", lat=51.5, lon=0, dates=days)

Neither engine is a dependency of the package: ``pip install
bsp_shadows[dask]`` or ``bsp_shadows[ray]``.
"""

from __future__ import annotations

from typing import Iterable, List

import numpy as np

from . import _native
from ._native import MAX_SUNS_A_RUN, Mesh, SunHours

__all__ = ["sun_hours", "runs_of", "tasks_of"]


def runs_of(suns: np.ndarray) -> List[np.ndarray]:
    """The study's suns in the runs one process makes, in order."""
    suns = np.ascontiguousarray(suns, dtype=np.float64)
    return [suns[i : i + MAX_SUNS_A_RUN] for i in range(0, len(suns), MAX_SUNS_A_RUN)]


def _run(mesh: Mesh, suns: np.ndarray, step_hours: float, threads: int | None, extremes: bool,
         tile=None) -> bytes:
    if threads is not None:
        _native.set_threads(threads)
    return _native._hours_run(mesh, suns, step_hours, extremes, tile)


def tasks_of(suns: np.ndarray, tiles: int = 1) -> List[tuple]:
    """The study's tasks in the order one process makes and folds them:
    each run of suns (``runs_of``), and within it each tile ``(index,
    tiles)`` (``None`` for a study not cut into tiles)."""
    if tiles < 1:
        raise ValueError(f"tiles: at least 1 a side, not {tiles}")
    cut = [None] if tiles == 1 else [(i, tiles) for i in range(tiles * tiles)]
    return [(run, tile) for run in runs_of(suns) for tile in cut]


def sun_hours(
    scene: Mesh,
    client,
    *,
    lat: float,
    lon: float,
    dates: Iterable,
    step_minutes: float = 10.0,
    utc_offset: float = 0.0,
    north: float = 0.0,
    up: str = "z",
    height: float = 0.0,
    threads_per_task: int | None = None,
    extremes: bool = True,
    tiles: int = 1,
) -> SunHours:
    """``bsp_shadows.sun_hours`` with the runs spread over ``client``: a
    ``dask.distributed.Client``, or ``"ray"`` for Ray's current cluster
    (``ray.init()`` first). ``threads_per_task`` caps the threads each task
    uses on its worker (default: the worker process's pool, which is the
    CPUs it may use; set it to the worker's CPUs when several workers share
    a machine). ``extremes`` and ``tiles``: as for
    ``bsp_shadows.sun_hours``; with ``tiles`` > 1 every run of suns is
    ``tiles²`` tasks, one a tile, each holding only its tile's shadows (for
    a scene too big for one worker's memory in one run), and the result is
    the single-process ``sun_hours(..., tiles=tiles)``, bit for bit."""
    suns = _native.study_suns(lat, lon, list(dates), step_minutes, utc_offset, north, up, height)
    step_hours = step_minutes / 60.0
    tasks = tasks_of(suns, tiles)
    if isinstance(client, str) and client == "ray":
        parts = _on_ray(scene, tasks, step_hours, threads_per_task, extremes)
    elif hasattr(client, "scatter") and hasattr(client, "gather"):
        parts = _on_dask(client, scene, tasks, step_hours, threads_per_task, extremes)
    else:
        raise TypeError("client: a dask.distributed.Client or the string 'ray'")
    return _native._fold_runs(scene, parts, suns, step_hours, tiles)


def _on_dask(client, scene, tasks, step_hours, threads, extremes):
    mesh = client.scatter(scene, broadcast=True)
    futures = [
        client.submit(_run, mesh, run, step_hours, threads, extremes, tile, pure=False,
                      key=f"bsp-sun-run-{i}-{id(tasks)}")
        for i, (run, tile) in enumerate(tasks)
    ]
    return client.gather(futures)


def _on_ray(scene, tasks, step_hours, threads, extremes):
    import ray

    task = ray.remote(_run)
    mesh = ray.put(scene)
    return ray.get([task.remote(mesh, run, step_hours, threads, extremes, tile) for run, tile in tasks])
