"""Fixtures of the Python module's tests: the command-line tool to compare with, real scans,
and readers for the files the tool writes (PNG through PIL, PFM here).

ctest runs these with PYTHONPATH=<build>/python and SUBSCAN_EXECUTABLE=<build>/src/subscan;
by hand: PYTHONPATH=build/python SUBSCAN_EXECUTABLE=build/src/subscan python3 -m pytest tests/python
"""
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import subscan

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]


def _executable():
    path = os.environ.get("SUBSCAN_EXECUTABLE") or str(SOURCE_DIR / "build" / "src" / "subscan")
    if not os.access(path, os.X_OK):
        pytest.fail(f"the subscan executable {path} is missing: build it, or set SUBSCAN_EXECUTABLE")
    return path


class Cli:
    """Runs `subscan ARGS` and returns what it printed; fails the test on a non-zero exit
    unless `expect_failure`."""

    def __init__(self, executable):
        self.executable = executable

    def __call__(self, *args, expect_failure=False):
        environment = dict(os.environ, SUBSCAN_GL_DEBUG="1")
        result = subprocess.run([self.executable, *map(str, args)], capture_output=True,
                                text=True, env=environment, timeout=300)
        if expect_failure:
            assert result.returncode != 0, f"subscan {args} succeeded"
            return result.stderr
        assert result.returncode == 0, f"subscan {args} failed: {result.stderr}"
        return result.stdout

    def json(self, *args):
        return json.loads(self(*args))

    def error(self, *args):
        """The one sentence the CLI prints for a failing command, without 'subscan: '."""
        stderr = self(*args, expect_failure=True).strip()
        assert stderr.startswith("subscan: "), stderr
        return stderr[len("subscan: "):]


@pytest.fixture(scope="session")
def cli():
    return Cli(_executable())


@pytest.fixture(scope="session")
def data_dir():
    """Real scans ($SUBSCAN_TEST_DATA or ../shared/data beside the checkout), or a visible
    skip."""
    directory = pathlib.Path(os.environ.get("SUBSCAN_TEST_DATA") or SOURCE_DIR.parent / "shared" / "data")
    if not directory.is_dir():
        pytest.skip(f"real scans not found in {directory} (set SUBSCAN_TEST_DATA)")
    return directory


@pytest.fixture(scope="session")
def sphere():
    """The built-in 4,000-point unit sphere: small enough for llvmpipe in milliseconds."""
    return subscan.load("synthetic:sphere")


@pytest.fixture(scope="session")
def sphere_renderer(sphere):
    """One renderer shared by the tests that only read from it: each new renderer compiles
    its shaders again (seconds on llvmpipe)."""
    with subscan.Renderer(sphere) as renderer:
        yield renderer


def read_png(path):
    from PIL import Image
    with Image.open(path) as image:
        return np.asarray(image)


def read_pfm(path):
    """A PFM as subscan writes it: 'Pf' (1 channel) or 'PF' (3), little-endian (negative
    scale), rows bottom to top; returned top row first, H×W or H×W×3 float32."""
    with open(path, "rb") as file:
        kind = file.readline().strip()
        width, height = map(int, file.readline().split())
        scale = float(file.readline())
        assert scale < 0, "subscan writes little-endian PFM"
        channels = 3 if kind == b"PF" else 1
        values = np.frombuffer(file.read(), dtype="<f4")
    assert values.size == width * height * channels
    image = values.reshape(height, width, channels)[::-1]
    return image[:, :, 0] if channels == 1 else image
