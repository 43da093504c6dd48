"""The package gives what the command line writes, for the same input."""

import json
import pickle

import numpy as np
import pytest

import bsp_shadows as bs
from conftest import MESHES, run_cli


@pytest.mark.parametrize("op", ["union", "intersection", "difference"])
def test_booleans_equal_the_cli_byte_for_byte(tmp_path, shadow_bin, sphere, op):
    moved = sphere.translated((0.31, 0.17, -0.05))
    a, b = tmp_path / "a.obj", tmp_path / "b.obj"
    sphere.write(a)
    moved.write(b)
    run_cli(shadow_bin, "csg", op, a, b, "-o", tmp_path / "cli.obj")
    ours = getattr(bs, op)(bs.read_mesh(a), bs.read_mesh(b))
    ours.write(tmp_path / "py.obj")
    assert (tmp_path / "py.obj").read_bytes() == (tmp_path / "cli.obj").read_bytes()
    operator = {"union": "__or__", "intersection": "__and__", "difference": "__sub__"}[op]
    again = getattr(bs.read_mesh(a), operator)(bs.read_mesh(b))
    assert (again.vertices == ours.vertices).all() and (again.faces == ours.faces).all()
    assert again.is_closed()


def test_lit_areas_equal_the_cli_json(tmp_path, shadow_bin, teapot):
    run_cli(
        shadow_bin,
        "shadows",
        MESHES / "teapot.obj",
        "--light", "2,3,5",
        "--sun", "1,1,3",
        "-o", tmp_path / "cli.json",
    )
    cli = json.loads((tmp_path / "cli.json").read_text())
    s = bs.shadows(teapot, [bs.PointLight((2, 3, 5)), bs.Sun((1, 1, 3))])
    lit = np.zeros_like(s.lit_area)
    for frag in cli["fragments"]:
        for i, on in enumerate(frag["lit"]):
            if on:
                lit[frag["face"], i] += frag["area"]
    assert (lit == s.lit_area).all()
    assert list(s.lit_area.sum(axis=0)) == cli["summary"]["lit_area"]
    frags = s.fragments()
    assert len(frags["face"]) == len(cli["fragments"])
    assert (frags["face"] == [f["face"] for f in cli["fragments"]]).all()
    # the outer rings' points are the JSON's vertices
    first = cli["fragments"][0]["vertices"]
    r0, r1 = frags["ring_points"][0], frags["ring_points"][1]
    assert (frags["points"][r0:r1] == np.array(first)).all()
    s.write(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()


def test_sun_hours_equal_the_cli(tmp_path, shadow_bin, yard):
    yard.write(tmp_path / "yard.obj")
    run_cli(
        shadow_bin, "sunhours", tmp_path / "yard.obj",
        "--lat", "51.5", "--lon", "-0.1", "--date", "2026-03-21", "--step", "20",
        "-o", tmp_path / "cli.csv",
    )
    rows = (tmp_path / "cli.csv").read_text().splitlines()[1:]
    cli = np.array([[float(x) for x in r.split(",")[2:]] for r in rows])
    h = bs.sun_hours(bs.read_mesh(tmp_path / "yard.obj"), lat=51.5, lon=-0.1,
                     dates=["2026-03-21"], step_minutes=20)
    ours = np.column_stack([h.area, h.per_face, h.min_hours, h.max_hours])
    assert (ours == cli).all()


def test_soft_shadows_equal_the_cli_json(tmp_path, shadow_bin, teapot):
    lamp = [(1, -1, 6), (3, -1, 6), (3, 1, 6), (1, 1, 6)][::-1]
    run_cli(
        shadow_bin,
        "shadows",
        MESHES / "teapot.obj",
        "--light", "2,3,5",
        "--area-light", ";".join(",".join(map(str, c)) for c in lamp),
        "--sun-disc", "1,1,3:2",
        "-o", tmp_path / "cli.json",
    )
    cli = json.loads((tmp_path / "cli.json").read_text())
    # given in another order than the CLI numbers them (points and suns
    # first): the columns follow the order given
    lights = [bs.AreaLight(lamp), bs.PointLight((2, 3, 5)), bs.SunDisc((1, 1, 3), 2.0)]
    s = bs.soft_shadows(teapot, lights)
    cols = [1, 0, 2]
    summary = cli["summary"]
    for name in ["lit_area", "penumbra_area", "umbra_area", "undecided_area"]:
        ours = getattr(s, name).sum(axis=0)
        assert np.allclose(ours, [summary[name][c] for c in cols], rtol=1e-12, atol=1e-12), name
    assert s.penumbra_area[:, 0].sum() > 0 and s.umbra_area[:, 0].sum() > 0
    assert s.penumbra_area[:, 1].sum() == 0  # a point light casts no penumbra
    total = s.lit_area + s.penumbra_area + s.umbra_area
    assert np.allclose(total, s.face_area[:, None], rtol=1e-9, atol=1e-12)
    assert s.fragment_count == len(cli["fragments"])
    # the fragments as arrays: the CLI's regions, bits and shares, the
    # lights in the order given
    frags = s.fragments()
    assert (frags["face"] == [f["face"] for f in cli["fragments"]]).all()
    for key in ["lit", "umbra", "undecided"]:
        bits = [sum(1 << i for i, c in enumerate(cols) if f[key][c]) for f in cli["fragments"]]
        assert (frags[key] == np.array(bits, dtype=np.uint64)).all(), key
    shares = [[np.nan if f["visible"][c] is None else f["visible"][c] for c in cols]
              for f in cli["fragments"]]
    assert np.array_equal(frags["visible"], np.array(shares), equal_nan=True)
    assert np.isfinite(frags["visible"][:, 0]).any()
    rings = frags["rings"]
    for i, f in enumerate(cli["fragments"]):
        want = [f["vertices"]] + f.get("holes", [])
        assert rings[i + 1] - rings[i] == len(want)
        for r, ring in zip(range(rings[i], rings[i + 1]), want):
            a, b = frags["ring_points"][r], frags["ring_points"][r + 1]
            assert (frags["points"][a:b] == np.array(ring)).all()
    assert any(len(f.get("holes", [])) > 0 for f in cli["fragments"])
    s.write(tmp_path / "py.json")
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    again = pickle.loads(pickle.dumps(s))
    assert (again.umbra_area == s.umbra_area).all()
    with pytest.raises(bs.LightError, match="at least three"):
        bs.AreaLight([(0, 0, 1), (1, 0, 1)])
    with pytest.raises(bs.LightError, match="light 1 is not"):
        bs.soft_shadows(teapot, [bs.PointLight((2, 3, 5)), "lamp"])


def test_region_hours_equal_the_cli(tmp_path, shadow_bin, yard):
    yard.write(tmp_path / "yard.obj")
    run_cli(
        shadow_bin, "sunhours", tmp_path / "yard.obj",
        "--lat", "51.5", "--lon", "-0.1", "--date", "2026-03-21", "--step", "20",
        "--regions", "0", "-o", tmp_path / "cli.csv",
    )
    rows = [r.split(",") for r in (tmp_path / "cli.csv").read_text().splitlines()[1:]]
    cells = bs.region_hours(bs.read_mesh(tmp_path / "yard.obj"), [0], lat=51.5, lon=-0.1,
                            dates=["2026-03-21"], step_minutes=20)
    assert (cells["face"] == 0).all()
    assert [float(r[3]) for r in rows] == list(cells["hours"])
    assert [float(r[4]) for r in rows] == list(cells["area"])
    assert len(cells["rings"]) == len(rows) + 1
    assert len(cells["ring_points"]) == cells["rings"][-1] + 1
    assert cells["points"].shape == (cells["ring_points"][-1], 3)
    h = bs.sun_hours(bs.read_mesh(tmp_path / "yard.obj"), lat=51.5, lon=-0.1,
                     dates=["2026-03-21"], step_minutes=20)
    assert abs(cells["area"].sum() - h.area[0]) < 1e-9 * h.area[0]
    assert cells["hours"].min() == h.min_hours[0] and cells["hours"].max() == h.max_hours[0]
    with pytest.raises(bs.BspError, match="no face is in a group `garden`"):
        bs.region_hours(bs.read_mesh(tmp_path / "yard.obj"), "garden", lat=51.5, lon=-0.1,
                        dates=["2026-03-21"])
