"""Exact mesh Booleans, shadows and sun-hours on numpy arrays.

Every geometric decision is exact for the input snapped to a grid fitted
to it (BSP trees, no epsilon); results are rounded once to float64.

    >>> import numpy as np, bsp_shadows as bs
    >>> cube = bs.box((0, 0, 0), (2, 2, 2))
    >>> moved = cube.translated((1, 1, 1))
    >>> (cube | moved).volume(), (cube & moved).volume(), (cube - moved).volume()
    (15.0, 1.0, 7.0)
    >>> s = bs.shadows(cube | bs.box((-5, -5, -1), (5, 5, 0)), [bs.Sun((0, 0, 1))])
    >>> float(s.lit_area.sum())
    100.0

The work runs without the GIL on a pool of ``get_threads()`` threads
(``set_threads(n)`` changes it; results do not depend on it).
"""

from __future__ import annotations

from typing import Iterable, Optional, Sequence

import numpy as np

from . import _native
from ._native import (
    MAX_SUNS_A_RUN,
    AreaLight,
    BspError,
    LightError,
    Mesh,
    MeshError,
    PointLight,
    Shadows,
    SoftShadows,
    Sun,
    SunDisc,
    SunHours,
    difference,
    get_threads,
    intersection,
    set_threads,
    shadows,
    sensor_intervals,
    soft_shadows,
    study_suns,
    union,
)

__all__ = [
    "AreaLight",
    "BspError",
    "LightError",
    "MAX_SUNS_A_RUN",
    "Mesh",
    "MeshError",
    "PointLight",
    "Shadows",
    "SoftShadows",
    "Sun",
    "SunDisc",
    "SunHours",
    "box",
    "difference",
    "from_trimesh",
    "get_threads",
    "intersection",
    "read_mesh",
    "region_hours",
    "set_threads",
    "shadows",
    "sensor_intervals",
    "soft_shadows",
    "study_suns",
    "sun_hours",
    "to_trimesh",
    "union",
]

__version__ = "0.1.0"


def read_mesh(path) -> Mesh:
    """Reads an OBJ, STL or CityJSON file (by its extension; .json is CityJSON, one group per city object)."""
    return Mesh.read(path)


def box(lo: Sequence[float], hi: Sequence[float]) -> Mesh:
    """The axis-aligned box from corner ``lo`` to corner ``hi``, as six
    outward-facing quads. ``lo`` must lie below ``hi`` on every axis
    (``MeshError`` otherwise: a box turned inside out, or flat, is no
    solid)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    if not (x0 < x1 and y0 < y1 and z0 < z1):
        raise MeshError(
            f"box: lo {tuple(lo)} must lie below hi {tuple(hi)} on every axis"
        )
    vertices = np.array(
        [[x, y, z] for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)],
        dtype=np.float64,
    )
    faces = np.array(
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    )
    return Mesh(vertices, faces)


def to_trimesh(mesh: Mesh):
    """A ``trimesh.Trimesh`` of ``mesh`` (needs trimesh)."""
    return mesh.to_trimesh()


def from_trimesh(mesh) -> Mesh:
    """The ``Mesh`` of a ``trimesh.Trimesh``."""
    return Mesh.from_trimesh(mesh)


def region_hours(
    scene: Mesh,
    faces,
    *,
    lat: float,
    lon: float,
    dates: Iterable,
    step_minutes: float = 10.0,
    utc_offset: float = 0.0,
    north: float = 0.0,
    up: str = "z",
    height: float = 0.0,
) -> dict:
    """The cells of some faces of ``scene`` over a study (the suns of
    ``sun_hours``): every step's exact lit parts of those faces overlaid,
    then merged where they see the same suns, so that each cell is a
    largest connected part of a face whose points see the same suns (not
    always convex, perhaps with holes). ``faces``: a group's name (a mesh
    read from a file or a built-in scene) or face ids.

    A dict of arrays: ``face`` (C,), ``hours`` (C,), ``area`` (C,) (holes
    taken out), ``rings`` (C+1,), ``ring_points`` (R+1,) and ``points``
    (P, 3): cell c's rings are ``rings[c]:rings[c+1]``, its boundary
    (counter-clockwise from the face's front) first, then its holes
    (clockwise), and ring r's corners are
    ``points[ring_points[r]:ring_points[r+1]]``.
    ``area[hours >= 2].sum() / area.sum()`` is the share of the BRE 209
    garden test on 21 March.
    """
    suns = study_suns(lat, lon, list(dates), step_minutes, utc_offset, north, up, height)
    if not isinstance(faces, str):
        faces = [int(f) for f in faces]
    return _native._region_hours(scene, suns, step_minutes / 60.0, faces)


def sun_hours(
    scene: Mesh,
    *,
    lat: float,
    lon: float,
    dates: Iterable,
    step_minutes: float = 10.0,
    utc_offset: float = 0.0,
    north: float = 0.0,
    up: str = "z",
    height: float = 0.0,
    extremes: bool = True,
    sun_disc: Optional[float] = None,
    tiles: int = 1,
) -> SunHours:
    """The sun-hours of every face of ``scene`` over a study: on each of
    ``dates`` (``datetime.date`` or ``"YYYY-MM-DD"``), a sun at the middle
    of every ``step_minutes`` interval of the day (local time at
    ``utc_offset`` hours) while it is above the horizon, at latitude
    ``lat`` and longitude ``lon`` (degrees north and east). ``north``: true
    north in degrees clockwise from the scene's north axis; ``up``: the
    scene's up axis, ``"z"`` or ``"y"``.

    The result's ``per_face`` is each face's mean hours (exact lit areas
    for every sun), ``min_hours``/``max_hours`` the fewest and most a point
    of it gets, and ``per_sensor(points)`` the exact hours at points.

    The extremes overlay every run's pieces of a face, which grows with the
    arrangement of all the suns' shadow edges on it (quadratic in the suns
    where many shadows cross one face, as on a ground under a detailed
    object). ``extremes=False`` leaves them NaN and costs the shadows alone;
    use it for long studies of large scenes, and ``per_sensor`` for hours
    at points.

    ``sun_disc`` (degrees; 0.2666 is the real sun's) counts each
    sun as a disc of that radius: a face's penumbra by the share of the disc
    it sees (mean hours only, the extremes NaN; far slower than point suns).

    ``tiles``: cut the scene into ``tiles × tiles`` tiles along its box's
    two longest axes, each run of suns shading one tile's faces past only
    what may shade them (less memory a run, and tasks to spread with
    ``bsp_shadows.distributed``). Every fragment's class is the whole
    scene's; the hours may differ from the uncut study's in their last bits.
    """
    suns = study_suns(lat, lon, list(dates), step_minutes, utc_offset, north, up, height)
    return _native._hours_of_suns(scene, suns, step_minutes / 60.0, extremes, sun_disc, tiles)
