"""Shared fixtures of the Python tests (ctest runs them with the build tree's package on PYTHONPATH)."""
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(os.environ.get("DYNID_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
CASES = ROOT / "cases"
SHARED = pathlib.Path(os.environ.get("DYNID_SHARED_DIR", ROOT.parent / "shared"))


@pytest.fixture(scope="session")
def cases():
    return CASES


@pytest.fixture(scope="session")
def shared():
    if not (SHARED / "data").is_dir():
        pytest.skip(f"shared data not found at {SHARED}")
    return SHARED


@pytest.fixture(scope="session")
def cli():
    """The dynid command of the same build (ctest sets DYNID_CLI)."""
    exe = os.environ.get("DYNID_CLI") or shutil.which("dynid")
    if not exe:
        pytest.skip("the dynid command is not known (set DYNID_CLI)")
    def run(*args, cwd=None, check=True):
        r = subprocess.run([exe, "--quiet", *map(str, args)], cwd=cwd, capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"dynid {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
        return r
    return run


def paper_frame_arrays():
    """The paper frame (cases/paper-frame) as NumPy arrays: 24 nodes, 31 members."""
    xy = np.array([[x, y] for y in range(6) for x in range(4)], dtype=float)
    cols = [[1 + 4 * s + line, 5 + 4 * s + line] for s in range(5) for line in range(4)]
    beams = [[5 + 4 * f + 2 * side, 6 + 4 * f + 2 * side] for f in range(5) for side in range(2)]
    elements = np.array(cols + beams + [[22, 23]], dtype=float)
    return xy, elements


PAPER_MATERIALS = {"steel": {"E": 210.0e9, "rho": 7800}}
PAPER_SECTIONS = {"member": {"A": 9.0e-5, "I": 2.0e-10}}
PAPER_SUPPORTS = [{"nodes": [1, 2, 3, 4], "fix": "all"}]


@pytest.fixture(scope="session")
def paper_frame():
    import dynid
    xy, el = paper_frame_arrays()
    return dynid.Model.from_arrays(xy, el, materials=PAPER_MATERIALS, sections=PAPER_SECTIONS, supports=PAPER_SUPPORTS)
