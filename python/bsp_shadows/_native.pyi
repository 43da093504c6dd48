"""Types of the compiled module ``bsp_shadows._native``."""

from os import PathLike
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike]
_Points = npt.ArrayLike
_Faces = Union[npt.ArrayLike, Sequence[Sequence[int]]]
_Light = Union["PointLight", "Sun"]
_AnyLight = Union["PointLight", "Sun", "AreaLight", "SunDisc"]

MAX_SUNS_A_RUN: int

class BspError(ValueError):
    """The base of this package's errors: input it refuses, with the library's message."""

class MeshError(BspError):
    """A mesh that cannot be used (the message names the face, and the edge for an open operand)."""

class LightError(BspError):
    """A light that cannot be placed."""

class Mesh:
    """A polygon mesh: vertices ``(n, 3)`` float64, faces ``(m, k)`` ints or a list of polygons."""

    def __init__(self, vertices: _Points, faces: _Faces, groups: Optional[Sequence[str]] = None) -> None: ...
    @property
    def groups(self) -> List[str]:
        """Each face's group name."""
    @property
    def group_names(self) -> List[str]:
        """The groups' names, in order of first use."""
    @staticmethod
    def read(path: _Path) -> "Mesh":
        """Reads an OBJ, STL or CityJSON (.json) file."""
    @staticmethod
    def scene(name: str) -> "Mesh":
        """A built-in scene: room, chair, cube, bunny, bunny-11k ... bunny-893k."""
    def write(self, path: _Path) -> None:
        """Writes OBJ or STL, by the extension."""
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """``(n, 3)`` float64 (a copy)."""
    @property
    def faces(self) -> Union[npt.NDArray[np.int64], List[npt.NDArray[np.int64]]]:
        """``(m, k)`` int64 when every face has k vertices, else a list of 1-D arrays."""
    def volume(self) -> float:
        """The enclosed volume, exact for the float64 positions and rounded once."""
    def is_closed(self) -> bool:
        """Whether every edge is met by two faces in opposite directions."""
    def translated(self, offset: Tuple[float, float, float]) -> "Mesh": ...
    def to_trimesh(self) -> Any:
        """A ``trimesh.Trimesh`` (polygons fanned), without trimesh's processing."""
    @staticmethod
    def from_trimesh(mesh: Any) -> "Mesh": ...
    def __or__(self, other: "Mesh") -> "Mesh": ...
    def __and__(self, other: "Mesh") -> "Mesh": ...
    def __sub__(self, other: "Mesh") -> "Mesh": ...

class PointLight:
    position: Tuple[float, float, float]
    def __init__(self, position: Tuple[float, float, float]) -> None: ...

class Sun:
    """A light infinitely far in ``direction`` (from the scene toward it)."""

    direction: Tuple[float, float, float]
    def __init__(self, direction: Tuple[float, float, float]) -> None: ...

class AreaLight:
    """A planar convex polygon light; it shines on the side its corners turn counter-clockwise about."""

    corners: List[Tuple[float, float, float]]
    def __init__(self, corners: Sequence[Tuple[float, float, float]]) -> None: ...

class SunDisc:
    """The sun as a disc of angular radius ``radius_deg`` toward ``direction``."""

    direction: Tuple[float, float, float]
    radius_deg: float
    def __init__(self, direction: Tuple[float, float, float], radius_deg: float = 0.2666) -> None: ...

class SoftShadows:
    """Lit, penumbra and umbra areas per face and light (columns in the order the lights were given)."""

    @property
    def lit_area(self) -> npt.NDArray[np.float64]:
        """``(faces, lights)``: the area that sees all of each light."""
    @property
    def penumbra_area(self) -> npt.NDArray[np.float64]:
        """``(faces, lights)``: the area that sees part of each light (undecided included)."""
    @property
    def umbra_area(self) -> npt.NDArray[np.float64]:
        """``(faces, lights)``: the area that sees none of each light."""
    @property
    def undecided_area(self) -> npt.NDArray[np.float64]:
        """``(faces, lights)``: penumbra that may be umbra (a quadric umbra boundary)."""
    @property
    def face_area(self) -> npt.NDArray[np.float64]: ...
    @property
    def fragment_count(self) -> int: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def lights(self) -> List[_AnyLight]: ...
    def fragments(self) -> Dict[str, npt.NDArray[Any]]:
        """Each fragment a maximal region of one face with one class per light (bits in the order given):
        ``face`` (F,), ``lit``, ``umbra``, ``undecided`` (F,) uint64 bits, ``visible`` (F, L) float64
        (NaN where not penumbra of an area light or sun disc), ``rings`` (F+1,), ``ring_points`` (R+1,),
        ``points`` (P, 3)."""
    def write(self, path: _Path) -> None:
        """JSON or OBJ, by the extension (the CLI's files; lights numbered points and suns first)."""

class Shadows:
    @property
    def lit_area(self) -> npt.NDArray[np.float64]:
        """``(faces, lights)``: the area of each face each light reaches."""
    @property
    def face_area(self) -> npt.NDArray[np.float64]: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def lights(self) -> List[_Light]: ...
    def lit_fraction(self, light: int) -> float: ...
    def fragments(self) -> Dict[str, npt.NDArray[Any]]:
        """``face`` (F,), ``lit`` (F,) uint64 bits, ``rings`` (F+1,), ``ring_points`` (R+1,), ``points`` (P, 3)."""
    def write(self, path: _Path) -> None:
        """JSON or OBJ, by the extension (the CLI's files)."""

class SunHours:
    @property
    def per_face(self) -> npt.NDArray[np.float64]: ...
    @property
    def min_hours(self) -> npt.NDArray[np.float64]: ...
    @property
    def max_hours(self) -> npt.NDArray[np.float64]: ...
    @property
    def area(self) -> npt.NDArray[np.float64]: ...
    @property
    def suns(self) -> npt.NDArray[np.float64]: ...
    @property
    def step_hours(self) -> float: ...
    def area_with_at_least(self, hours: float) -> npt.NDArray[np.float64]: ...
    def per_sensor(self, points: _Points) -> npt.NDArray[np.float64]:
        """The exact sun-hours at each point (``(p, 3)``), among the mesh's
        faces; or at each sensor ``(p, 6)``: a point and its surface's
        normal, counting only the suns in front of that surface."""

def union(a: Mesh, b: Mesh) -> Mesh: ...
def intersection(a: Mesh, b: Mesh) -> Mesh: ...
def difference(a: Mesh, b: Mesh) -> Mesh: ...
def shadows(mesh: Mesh, lights: Iterable[_Light]) -> Shadows: ...
def _region_hours(
    mesh: Mesh, suns: _Points, step_hours: float, faces: Union[str, Sequence[int]]
) -> Dict[str, npt.NDArray[Any]]: ...
def soft_shadows(mesh: Mesh, lights: Iterable[_AnyLight]) -> SoftShadows: ...
def study_suns(
    lat: float,
    lon: float,
    dates: Iterable[Any],
    step_minutes: float = ...,
    utc_offset: float = ...,
    north: float = ...,
    up: str = ...,
    height: float = ...,
) -> npt.NDArray[np.float64]: ...
def sensor_intervals(
    scene: Mesh,
    points: _Points,
    lat: float,
    lon: float,
    dates: Iterable[Any],
    utc_offset: float = ...,
    north: float = ...,
    up: str = ...,
    height: float = ...,
) -> List[List[npt.NDArray[np.float64]]]:
    """Each sensor's sun-on intervals on each day in closed form (no time
    sampling): per sensor, per day, an (n, 2) array of hours of the day's
    clock. Per hour the sun's arc from SPA at the hour's middle; no
    refraction."""

def set_threads(n: Optional[int] = ...) -> None: ...
def get_threads() -> int: ...
def _hours_of_suns(
    mesh: Mesh,
    suns: _Points,
    step_hours: float,
    extremes: bool = ...,
    sun_disc: Optional[float] = ...,
    tiles: int = ...,
) -> SunHours: ...
def _hours_run(
    mesh: Mesh, suns: _Points, step_hours: float, extremes: bool = ..., tile: Optional[Tuple[int, int]] = ...
) -> bytes: ...
def _mesh_of_flat(
    vertices: _Points,
    indices: npt.NDArray[np.uint32],
    starts: npt.NDArray[np.uint64],
    groups: npt.NDArray[np.uint32],
    names: List[str],
) -> Mesh: ...
def _study_scenes_made() -> int: ...
def _fold_runs(mesh: Mesh, runs: List[bytes], suns: _Points, step_hours: float, tiles: int = ...) -> SunHours: ...
