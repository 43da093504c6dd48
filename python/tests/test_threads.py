"""The thread count changes nothing but the time."""

import bsp_shadows as bs


def test_threads_change_nothing(sphere, yard):
    default = bs.get_threads()
    assert default >= 1
    results = []
    try:
        for n in [1, 2, 3]:
            bs.set_threads(n)
            assert bs.get_threads() == n
            u = sphere | sphere.translated((0.2, 0.1, 0.0))
            s = bs.shadows(yard, [bs.PointLight((3, 4, 20)), bs.Sun((1, 2, 4))])
            h = bs.sun_hours(yard, lat=40.0, lon=-3.7, dates=["2026-12-21"], step_minutes=30)
            results.append((u.vertices, u.faces, s.lit_area, h.per_face, h.min_hours))
    finally:
        bs.set_threads(None)
    assert bs.get_threads() == default
    for other in results[1:]:
        for a, b in zip(results[0], other):
            assert a.shape == b.shape and (a == b).all()


def test_the_gil_is_released(yard):
    """Two Python threads shading at once both finish, with the same
    answer (each call runs without the GIL)."""
    from concurrent.futures import ThreadPoolExecutor

    lights = [bs.Sun((1, 2, 4))]
    with ThreadPoolExecutor(2) as pool:
        a, b = pool.map(lambda _: bs.shadows(yard, lights).lit_area, range(2))
    assert (a == b).all()


def test_too_many_threads_is_an_error():
    import pytest

    with pytest.raises(bs.BspError, match="at most 1024"):
        bs.set_threads(100_000)
    assert bs.get_threads() >= 1
