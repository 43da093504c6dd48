"""Sun studies on Dask and Ray (on the loopback only) give one process's
numbers, bit for bit."""

import numpy as np
import pytest

import bsp_shadows as bs
import bsp_shadows.distributed as bsd

STUDY = dict(lat=51.5, lon=-0.1, dates=["2026-03-21", "2026-06-21"], step_minutes=10)


@pytest.fixture(scope="module")
def single(yard):
    h = bs.sun_hours(yard, **STUDY)
    # more suns than one run takes: several runs to fold
    assert len(h.suns) > 2 * bs.MAX_SUNS_A_RUN
    return h


def same(a, b):
    for name in ["per_face", "min_hours", "max_hours", "area", "suns"]:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and (x == y).all(), name


def test_runs_folded_in_process(yard, single):
    runs = [bs._native._hours_run(yard, r, single.step_hours) for r in bsd.runs_of(single.suns)]
    same(bs._native._fold_runs(yard, runs, single.suns, single.step_hours), single)
    with pytest.raises(bs.BspError, match="run 0 is not"):
        bs._native._fold_runs(yard, [runs[0][:-8]], single.suns, single.step_hours)
    other = bs._native._hours_run(bs.box((0, 0, 0), (1, 1, 1)), single.suns[:3], single.step_hours)
    with pytest.raises(bs.BspError, match="run 1 is of a mesh of 6 faces"):
        bs._native._fold_runs(yard, [runs[0], other], single.suns, single.step_hours)


@pytest.fixture(scope="module")
def tiled(yard, single):
    h = bs.sun_hours(yard, tiles=2, **STUDY)
    # every fragment's class is the whole scene's: the hours agree to the
    # last bits, and the cut is not the uncut study
    for name in ["per_face", "min_hours", "max_hours"]:
        assert np.abs(getattr(h, name) - getattr(single, name)).max() < 1e-9, name
    assert (h.area == single.area).all()
    return h


def test_tiles_folded_in_process(yard, single, tiled):
    tasks = bsd.tasks_of(single.suns, 2)
    assert len(tasks) == 4 * len(bsd.runs_of(single.suns))
    parts = [bs._native._hours_run(yard, run, single.step_hours, True, tile) for run, tile in tasks]
    same(bs._native._fold_runs(yard, parts, single.suns, single.step_hours, 2), tiled)
    # a tile's run is smaller than the whole run of its suns: only its
    # faces' pieces
    whole = bs._native._hours_run(yard, tasks[0][0], single.step_hours)
    assert max(map(len, parts[:4])) < len(whole)
    # pickled, the study is made again with its tiles
    import pickle

    # a copy of the scene (as each task on Ray gets) finds the scene the
    # last copy's run snapped
    def run_on_a_copy():
        copy = pickle.loads(pickle.dumps(yard))
        return bs._native._hours_run(copy, tasks[1][0], single.step_hours, True, tasks[1][1])

    assert run_on_a_copy() == parts[1]
    made = bs._native._study_scenes_made()
    assert run_on_a_copy() == parts[1] and bs._native._study_scenes_made() == made
    other = bs.box((0, 0, 0), (1, 1, 1))
    bs._native._hours_run(other, tasks[0][0], single.step_hours)
    assert bs._native._study_scenes_made() == made + 1

    same(pickle.loads(pickle.dumps(tiled)), tiled)
    with pytest.raises(bs.BspError, match="tile 4 of a study cut into 2 × 2 tiles"):
        bs._native._hours_run(yard, tasks[0][0], single.step_hours, True, (4, 2))
    with pytest.raises(ValueError, match="tiles"):
        bsd.tasks_of(single.suns, 0)


def test_dask_local_cluster(yard, single, tiled):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None, silence_logs=40,
    ) as cluster, distributed.Client(cluster) as client:
        h = bsd.sun_hours(yard, client, threads_per_task=1, **STUDY)
        cut = bsd.sun_hours(yard, client, threads_per_task=1, tiles=2, **STUDY)
    same(h, single)
    same(cut, tiled)
    points = np.array([[0.0, -3.0, 0.01], [6.0, 5.0, 0.01]])
    assert (h.per_sensor(points) == single.per_sensor(points)).all()


def test_ray_local(yard, single, tiled):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False,
             configure_logging=False, _node_ip_address="127.0.0.1")
    try:
        h = bsd.sun_hours(yard, "ray", threads_per_task=1, **STUDY)
        cut = bsd.sun_hours(yard, "ray", threads_per_task=1, tiles=2, **STUDY)
    finally:
        ray.shutdown()
    same(h, single)
    same(cut, tiled)


def test_dask_without_extremes(yard, single):
    distributed = pytest.importorskip("distributed")
    mean = bs.sun_hours(yard, extremes=False, **STUDY)
    # (the mean alone takes its lit areas from the trees' building, the
    # full study from the fragments: the same to rounding)
    assert np.abs(mean.per_face - single.per_face).max() < 1e-9
    assert np.isnan(mean.min_hours).all()
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None, silence_logs=40,
    ) as cluster, distributed.Client(cluster) as client:
        h = bsd.sun_hours(yard, client, extremes=False, **STUDY)
    assert (h.per_face == mean.per_face).all() and np.isnan(h.max_hours).all()
    import pickle

    back = pickle.loads(pickle.dumps(h))
    assert (back.per_face == h.per_face).all() and np.isnan(back.min_hours).all()


def test_bad_client(yard):
    with pytest.raises(TypeError):
        bsd.sun_hours(yard, object(), **STUDY)
