"""Shared fixtures: the repository's meshes and the CLI binary built by
the README's test command (scripts/test), so the package is checked against
what the command line writes."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import bsp_shadows as bs

ROOT = pathlib.Path(__file__).resolve().parents[2]
MESHES = ROOT / "data" / "meshes"


@pytest.fixture(scope="session")
def shadow_bin():
    path = pathlib.Path(os.environ.get("BSP_SHADOW_BIN", ROOT / "target" / "release" / "shadow"))
    assert path.exists(), f"{path}: build the CLI first (cargo build --release -p shadow-cli)"
    return path


def run_cli(binary, *args):
    subprocess.run([str(binary), *map(str, args), "--quiet"], check=True)


@pytest.fixture(scope="session")
def sphere():
    return bs.read_mesh(MESHES / "pyvista_sphere.obj")


@pytest.fixture(scope="session")
def teapot():
    return bs.read_mesh(MESHES / "teapot.obj")


@pytest.fixture(scope="session")
def yard():
    """A ground with three boxes on it: shadows that fall on the ground and
    on each other."""
    scene = bs.box((-20, -20, -1), (20, 20, 0))
    for lo, hi in [((-2, -2, 0), (2, 2, 6)), ((5, -1, 0), (7, 3, 3)), ((-8, 4, 0), (-5, 6, 9))]:
        scene = scene | bs.box(lo, hi)
    return scene


def tet():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return v, f
