import pickle

import numpy as np
import pytest

import bsp_shadows as bs
from conftest import MESHES, tet


def test_arrays_in_and_out():
    v, f = tet()
    m = bs.Mesh(v, f)
    assert m.vertices.dtype == np.float64 and m.vertices.shape == (4, 3)
    assert (m.vertices == v).all() and (m.faces == f).all()
    assert m.is_closed()
    assert m.volume() == 1 / 6
    # other dtypes and lists convert; a list of polygons of mixed sizes too
    assert (bs.Mesh(v.astype(np.float32), f.astype(np.uint32)).faces == f).all()
    assert (bs.Mesh(v.tolist(), f.tolist()).vertices == v).all()
    pyramid = bs.Mesh(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]],
        [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
    )
    assert isinstance(pyramid.faces, list) and len(pyramid.faces) == 5
    assert pyramid.volume() == 1 / 3
    assert pyramid.is_closed()


def test_built_in_scenes():
    room = bs.Mesh.scene("room")
    assert len(room.vertices) > 100 and not room.is_closed()
    assert bs.Mesh.scene("cube").volume() == 1.0
    with pytest.raises(bs.BspError, match="unknown scene `nope`"):
        bs.Mesh.scene("nope")


def test_exact_volume():
    cube = bs.box((0, 0, 0), (0.1, 0.1, 0.1))
    far = cube.translated((1e9, -3e9, 2e9))
    v = far.vertices
    sides = v.max(axis=0) - v.min(axis=0)
    # the f64 sides as stored, multiplied exactly (few bits each)
    assert far.volume() == sides[0] * sides[1] * sides[2]
    assert bs.box((-1, -2, -3), (2, 2, 2)).volume() == 60.0


def test_bad_input_raises_with_a_message(tmp_path):
    v, f = tet()
    with pytest.raises(bs.MeshError, match="face 1 names vertex 7"):
        bs.Mesh(v, [[0, 2, 1], [0, 1, 7]])
    with pytest.raises(bs.MeshError, match="fewer than 3"):
        bs.Mesh(v, [[0, 2, 1], [0, 1]])
    # indices that are not whole numbers were cut (2.9 taken for 2, True
    # for 1); whole floats are indices
    for faces in [np.asarray(f) + 0.9, np.asarray(f) > 0, [[0, 2, 1.5]]]:
        with pytest.raises(bs.MeshError, match="whole numbers"):
            bs.Mesh(v, faces)
    assert (bs.Mesh(v, np.asarray(f, dtype=float)).faces == bs.Mesh(v, f).faces).all()
    # indices numpy's cast to int64 would wrap to negative numbers are
    # named as given
    huge = np.asarray(f, dtype=np.uint64)
    huge[2, 1] = np.iinfo(np.uint64).max
    with pytest.raises(bs.MeshError, match="face 2 names vertex 18446744073709551615,"):
        bs.Mesh(v, huge)
    with pytest.raises(bs.MeshError, match="face 1 names vertex 18446744073709551615,"):
        bs.Mesh(v, [f[0], list(huge[2])])
    far = np.asarray(f, dtype=float)
    far[3, 0] = 1e20
    with pytest.raises(bs.MeshError, match="face 3 names vertex 1e\\+20,"):
        bs.Mesh(v, far)
    with pytest.raises(bs.MeshError, match="shape"):
        bs.Mesh(v[:, :2], f)
    bad = v.copy()
    bad[2, 1] = np.nan
    with pytest.raises(bs.MeshError, match="row 2 is not finite"):
        bs.Mesh(bad, f)
    # an open operand: the message names the face and the edge
    open_tet = bs.Mesh(v, f[:3])
    with pytest.raises(bs.MeshError, match=r"edge .* of face \d+ is a boundary edge"):
        open_tet | bs.Mesh(v, f)
    with pytest.raises(OSError):
        bs.read_mesh(MESHES / "no such mesh.obj")
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0\nf 1 2 3\n")
    with pytest.raises(bs.MeshError, match=r"bad.obj:2: vertex has 2"):
        bs.read_mesh(tmp_path / "bad.obj")
    with pytest.raises(bs.LightError, match="neither"):
        bs.shadows(bs.Mesh(v, f), ["a lamp"])
    with pytest.raises(bs.LightError):
        bs.shadows(bs.Mesh(v, f), [bs.Sun((0, 0, 0))])
    with pytest.raises(bs.LightError):
        bs.shadows(bs.Mesh(v, f), [bs.Sun((0, 0, 1))] * 65)
    nan = float("nan")
    for lo, hi in [((1, 0, 0), (0, 1, 1)), ((0, 0, 0), (1, 1, 0)), ((0, 0, 0), (1, nan, 1))]:
        with pytest.raises(bs.MeshError, match="must lie below hi"):
            bs.box(lo, hi)
    with pytest.raises(bs.LightError, match="light 1: a coordinate is not finite"):
        bs.shadows(bs.Mesh(v, f), [bs.Sun((0, 0, 1)), bs.PointLight((nan, 0, 3))])
    with pytest.raises(bs.LightError, match="light 0: a coordinate is not finite"):
        bs.soft_shadows(bs.Mesh(v, f), [bs.AreaLight([(0, 0, 3), (1, 0, 3), (0, nan, 3)])])
    assert issubclass(bs.MeshError, ValueError)
    # faces left out on the grid are said, not only zeros
    far = np.vstack([v, v + 1e9])
    with pytest.warns(UserWarning, match="have no area on the grid"):
        s = bs.shadows(bs.Mesh(far, np.vstack([f, f + 4])), [bs.Sun((0, 0, 1))])
    assert (s.face_area == 0).any()


def test_pickle_round_trips(sphere, yard):
    for obj in [sphere, bs.PointLight((1.0, 2.0, 3.0)), bs.Sun((0.0, 0.5, 1.0))]:
        back = pickle.loads(pickle.dumps(obj))
        assert repr(back) == repr(obj)
    back = pickle.loads(pickle.dumps(sphere))
    assert (back.vertices == sphere.vertices).all() and (back.faces == sphere.faces).all()
    s = bs.shadows(yard, [bs.PointLight((3, 4, 20)), bs.Sun((1, 2, 4))])
    t = pickle.loads(pickle.dumps(s))
    assert (t.lit_area == s.lit_area).all()
    h = bs.sun_hours(yard, lat=51.5, lon=0.0, dates=["2026-06-21"], step_minutes=30)
    g = pickle.loads(pickle.dumps(h))
    assert (g.per_face == h.per_face).all() and (g.suns == h.suns).all()


def test_trimesh_both_ways(sphere):
    trimesh = pytest.importorskip("trimesh")
    t = sphere.to_trimesh()
    assert isinstance(t, trimesh.Trimesh) and t.is_watertight
    assert abs(t.volume - sphere.volume()) < 1e-9 * abs(sphere.volume())
    back = bs.from_trimesh(t)
    assert (back.vertices == sphere.vertices).all()
    u = bs.union(back, back.translated((0.3, 0.0, 0.0)))
    assert bs.to_trimesh(u).is_watertight


def test_the_package_docstring_examples():
    import doctest

    result = doctest.testmod(bs)
    assert result.attempted >= 4 and result.failed == 0


def test_groups_name_faces_and_survive_pickling(tmp_path):
    v, f = tet()
    m = bs.Mesh(v, f, groups=["base", "side", "side", "top"])
    assert m.group_names == ["base", "side", "top"]
    assert m.groups == ["base", "side", "side", "top"]
    back = pickle.loads(pickle.dumps(m))
    assert back.groups == m.groups and (back.faces == m.faces).all()
    # a mesh without names is one group; a file's groups come back
    assert bs.Mesh(v, f).groups == ["default"] * 4
    m.write(tmp_path / "t.obj")
    read = bs.read_mesh(tmp_path / "t.obj")
    assert read.groups == m.groups
    assert pickle.loads(pickle.dumps(read)).groups == m.groups
    room = bs.Mesh.scene("room")
    assert "floor" in room.group_names
    assert pickle.loads(pickle.dumps(room)).groups == room.groups

    # a region study of a group by its name
    cells = bs.region_hours(m, "base", lat=51.5, lon=0.0, dates=["2026-06-21"], step_minutes=60)
    assert (cells["face"] == 0).all()
    with pytest.raises(bs.MeshError, match="3 group names for 4 faces"):
        bs.Mesh(v, f, groups=["a", "b", "c"])


def test_a_cityjson_block_reads_with_its_objects_as_groups(tmp_path):
    block = MESHES.parent / "city" / "block.city.json"
    m = bs.read_mesh(block)
    assert m.group_names == ["house", "tower-part", "tree-1", "yard"]
    # hours per face, each face in its building's group
    hours = bs.sun_hours(m, lat=52.01, lon=4.36, dates=["2026-06-21"], step_minutes=60)
    assert len(hours.per_face) == len(m.groups)
    yard = [a for a, g in zip(hours.area, m.groups) if g == "yard"]
    assert sum(yard) == pytest.approx(3500.0, abs=1e-6)
    bad = tmp_path / "bad.city.json"
    bad.write_text(block.read_text().replace('"CityObjects"', '"Objects"', 1))
    with pytest.raises(bs.MeshError, match="bad.city.json: /CityObjects: missing"):
        bs.read_mesh(bad)


def test_sensor_intervals_in_closed_form_agree_with_sampled_hours():
    m = bs.read_mesh(MESHES.parent / "city" / "block.city.json")
    points = np.array([[85005.0, 446015.0, 0.0], [85034.0, 446021.0, 0.0], [85005.0, 446055.0, 0.0]])
    days = ["2026-03-21", "2026-06-21"]
    on = bs.sensor_intervals(m, points, lat=52.01, lon=4.36, dates=days)
    assert len(on) == 3 and all(len(d) == 2 for d in on)
    exact = np.array([sum((iv[:, 1] - iv[:, 0]).sum() for iv in d) for d in on])
    for d in on:
        for iv in d:
            assert iv.shape[1] == 2 and (iv[:, 0] < iv[:, 1]).all()
            assert (iv[1:, 0] >= iv[:-1, 1]).all()  # sorted, disjoint
    study = bs.sun_hours(m, lat=52.01, lon=4.36, dates=days, step_minutes=5, extremes=False)
    sampled = study.per_sensor(points)
    # the refraction left out and the steps at shadow edges, for two days
    assert np.abs(exact - sampled).max() < 0.75, (exact, sampled)
    assert exact[1] < exact[2] - 2.0
    # sensors that face a way: up, as points; down, no sun; east, its
    # morning only, sampled and exact alike
    for n, check in [((0, 0, 1), "same"), ((0, 0, -1), "none"), ((1, 0, 0), "less")]:
        facing = np.hstack([points, np.tile(np.array(n, float), (3, 1))])
        f_sampled = study.per_sensor(facing)
        f_on = bs.sensor_intervals(m, facing, lat=52.01, lon=4.36, dates=days)
        f_exact = np.array([sum((iv[:, 1] - iv[:, 0]).sum() for iv in d) for d in f_on])
        assert np.abs(f_exact - f_sampled).max() < 0.75, (n, f_exact, f_sampled)
        if check == "same":
            assert (f_sampled == sampled).all() and np.allclose(f_exact, exact)
        elif check == "none":
            assert (f_sampled == 0).all() and (f_exact == 0).all()
        else:
            assert (f_sampled < sampled - 1.0).all() and (f_sampled > 0).all(), (f_sampled, sampled)
    with pytest.raises(bs.MeshError, match="normal is zero"):
        study.per_sensor(np.array([[0.0, 0, 0, 0, 0, 0]]))
    with pytest.raises(bs.MeshError, match=r"not \(n, 3\) \(points\) or \(n, 6\)"):
        study.per_sensor(np.zeros((1, 4)))


def test_a_sun_disc_study_matches_point_suns_on_a_lone_box():
    box = bs.box((0, 0, 0), (1, 2, 3))
    kw = dict(lat=51.5, lon=0.0, dates=["2026-03-21"], step_minutes=60)
    point = bs.sun_hours(box, extremes=False, **kw)
    disc = bs.sun_hours(box, sun_disc=0.2666, **kw)
    # nothing to cast a penumbra on: the same hours, no extremes
    assert np.allclose(disc.per_face, point.per_face, rtol=0, atol=1e-9)
    assert np.isnan(disc.min_hours).all()


def test_a_pickled_disc_study_stays_a_disc_study(yard):
    kw = dict(lat=51.5, lon=0.0, dates=["2026-03-21"], step_minutes=120)
    disc = bs.sun_hours(yard, sun_disc=2.0, **kw)
    point = bs.sun_hours(yard, extremes=False, **kw)
    # a wide disc's penumbrae change the ground's hours
    assert np.abs(disc.per_face - point.per_face).max() > 1e-3
    back = pickle.loads(pickle.dumps(disc))
    assert (back.per_face == disc.per_face).all()
    with pytest.raises(bs.BspError, match="not cut into tiles"):
        bs.sun_hours(yard, sun_disc=2.0, tiles=2, **kw)


def test_meshes_of_mixed_faces_pickle_as_flat_arrays():
    city = bs.Mesh.scene("city")
    assert isinstance(city.faces, list)  # triangles and quads
    corners = sum(len(f) for f in city.faces)
    b = pickle.dumps(city)
    # the buffers and little else: no Python object a face
    arrays = city.vertices.nbytes + 4 * corners + 8 * (len(city.faces) + 1) + 4 * len(city.faces)
    assert len(b) < arrays + 4096, (len(b), arrays)
    back = pickle.loads(b)
    assert (back.vertices == city.vertices).all() and back.groups == city.groups
    assert all((np.asarray(x) == np.asarray(y)).all() for x, y in zip(back.faces, city.faces))
    # arrays that do not make a mesh are refused
    v = np.zeros((3, 3))
    ids = lambda *a: np.array(a, dtype=np.uint32)  # noqa: E731
    starts = lambda *a: np.array(a, dtype=np.uint64)  # noqa: E731
    with pytest.raises(bs.MeshError, match="names vertex 5 of 3"):
        bs._native._mesh_of_flat(v, ids(0, 1, 5), starts(0, 3), ids(0), ["a"])
    with pytest.raises(bs.MeshError, match="do not fit"):
        bs._native._mesh_of_flat(v, ids(0, 1, 2), starts(0, 4), ids(0), ["a"])
    with pytest.raises(bs.MeshError, match="fewer than 3"):
        bs._native._mesh_of_flat(v, ids(0, 1, 2), starts(0, 2, 3), ids(0, 0), ["a"])
    with pytest.raises(bs.MeshError, match="group"):
        bs._native._mesh_of_flat(v, ids(0, 1, 2), starts(0, 3), ids(1), ["a"])
