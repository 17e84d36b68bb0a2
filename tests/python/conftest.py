"""Shared by the Python module's tests (ctest `python`): the module built in the build folder
(PYTHONPATH), the mcfbench command beside it (MCFBENCH_BINARY), and a reader of the binary PLY
files it writes, independent of the module."""

import os
import subprocess

import numpy as np
import pytest


@pytest.fixture(scope="session")
def mcfbench_binary():
    path = os.environ.get("MCFBENCH_BINARY")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("MCFBENCH_BINARY must name the built mcfbench command")
    return path


def run_cli(binary, *args):
    """Runs `mcfbench ARGS...`; fails the test with its stderr if it exits non-zero."""
    r = subprocess.run([binary, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


def read_ply(path):
    """(V, F) of a binary little-endian PLY as mcfbench writes it: double x, y, z per vertex and
    a uchar-counted list of int per face (the header says so; anything else is refused)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0", header
    nv = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
    nf = next(int(l.split()[2]) for l in header if l.startswith("element face"))
    assert [l for l in header if l.startswith("property")] == [
        "property double x", "property double y", "property double z",
        "property list uchar int vertex_indices"], header
    V = np.frombuffer(data, dtype="<f8", count=3 * nv, offset=end).reshape(nv, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]), count=nf,
                          offset=end + 24 * nv)
    assert (faces["n"] == 3).all()
    return V, faces["i"].astype(np.int64)
