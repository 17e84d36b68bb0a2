"""mcfbench.flow against the command line it wraps: the same options give the same flow, bit for
bit, and the same result record; its callback, frames and errors."""

import json
import os
import signal
import threading

import numpy as np
import pytest

import mcfbench
from conftest import read_ply, run_cli


def test_final_positions_equal_the_command_lines_final_ply_bit_for_bit(mcfbench_binary, tmp_path):
    # A catalogue model, cMCF at unit area with CHOLMOD (the README's "One flow"), on one thread
    # in both: a cMCF flow on two threads differs in its last bits from run to run of the same
    # command.
    args = dict(flow="cmcf", normalize_area=True, dt=1e-3, steps=4, save_every=2, threads=1)
    out = tmp_path / "bunny"
    run_cli(mcfbench_binary, "flow", "--mesh", "cgal:bunny00", "--flow", "cmcf", "--normalize-area",
            "--dt", "1e-3", "--steps", "4", "--save-every", "2", "--threads", "1", "--out", str(out))
    r = mcfbench.flow(mesh="cgal:bunny00", **args)
    V, F = read_ply(out / "final.ply")
    assert r.V.dtype == np.float64 and r.V.shape == V.shape
    assert np.array_equal(r.V, V)  # bit for bit
    assert np.array_equal(r.F, F)
    assert sorted(r.frames) == [0, 2, 4]
    for step, frame in r.frames.items():
        assert np.array_equal(frame, read_ply(out / ("frame_%05d.ply" % step))[0])
    cli = json.loads((out / "result.json").read_text())
    assert r.result["config"] == cli["config"]
    assert r.result["mesh"] == cli["mesh"]
    assert r.result["stop"] == cli["stop"] == {"step": 4, "reason": "completed"}
    # The same keys, per step too; the times and the machine's state differ.
    assert set(r.result) == set(cli)
    assert [set(s) for s in r.result["steps"]] == [set(s) for s in cli["steps"]]
    assert [s["solver"]["residuals"] for s in r.result["steps"]] == \
        [s["solver"]["residuals"] for s in cli["steps"]]


def test_arrays_flow_as_the_same_mesh_from_a_spec():
    V, F = mcfbench.load_mesh("icosphere:level=2")
    from_arrays = mcfbench.flow(V, F, steps=3, threads=1)
    from_spec = mcfbench.flow(mesh="icosphere:level=2", steps=3, threads=1)
    assert np.array_equal(from_arrays.V, from_spec.V)
    assert from_arrays.result["mesh"]["spec"] == "arrays"
    # int32 faces and a float32 copy of V are taken as well (converted).
    assert np.array_equal(mcfbench.flow(V, F.astype(np.int32), steps=3, threads=1).V, from_spec.V)


def test_a_config_dict_and_keywords_give_the_command_lines_config():
    r = mcfbench.flow(mesh="icosphere:level=2", config={"solver": {"name": "pcg"}, "steps": 2},
                      preconditioner="ichol", tolerance=1e-12, frozen=True, integrator="bdf2",
                      threads=1)
    c = r.result["config"]
    assert c["solver"]["name"] == "pcg" and c["solver"]["preconditioner"] == "ichol"
    assert c["solver"]["tolerance"] == 1e-12 and c["extrapolate"] is False
    assert c["steps"] == 2 and len(r.result["steps"]) == 2


def test_the_callback_sees_every_step_and_can_stop_the_flow():
    seen = []

    def callback(step, t, V):
        seen.append((step, t, V.shape))
        return step == 3

    r = mcfbench.flow(mesh="icosphere:level=2", dt=1e-3, steps=10, threads=1, callback=callback)
    assert [s for s, _, _ in seen] == [0, 1, 2, 3]
    assert seen[2][1] == 2e-3 and seen[0][2] == (162, 3)
    assert r.result["status"] == "ok"
    assert r.result["stop"] == {"step": 3, "reason": "stopped by the caller"}
    assert len(r.result["steps"]) == 3
    whole = mcfbench.flow(mesh="icosphere:level=2", dt=1e-3, steps=3, threads=1)
    assert np.array_equal(r.V, whole.V)


def test_an_exception_in_the_callback_reaches_the_caller_unchanged():
    class Mine(Exception):
        pass

    def callback(step, t, V):
        if step == 2:
            raise Mine("from the callback")

    with pytest.raises(Mine, match="from the callback"):
        mcfbench.flow(mesh="icosphere:level=2", steps=10, threads=1, callback=callback)


def test_ctrl_c_ends_the_flow_after_the_running_step():
    seen = []

    def callback(step, t, V):
        seen.append(step)
        if step == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        mcfbench.flow(mesh="icosphere:level=2", steps=50, threads=1, callback=callback)
    assert seen[-1] <= 2


def test_the_flow_runs_without_the_gil():
    # While the flow runs in a thread, this one counts. With the GIL held through the flow, the
    # count would stay near zero until the flow had run all its steps (minutes); released, it
    # runs at once, and the flow's callback sees the count's end and stops the flow.
    started, done = threading.Event(), threading.Event()
    box = {}

    def callback(step, t, V):
        started.set()
        return done.is_set()

    def run():
        box["r"] = mcfbench.flow(mesh="icosphere:level=2", steps=100000, threads=1, callback=callback)

    worker = threading.Thread(target=run)
    worker.start()
    assert started.wait(60)
    count = 0
    while count < 100000:
        count += 1
    alive = worker.is_alive()
    done.set()
    worker.join(60)
    assert alive and not worker.is_alive()
    assert box["r"].result["stop"]["reason"] == "stopped by the caller"
    assert box["r"].result["stop"]["step"] < 100000


@pytest.mark.parametrize("options, message", [
    (dict(cylces=2), 'unknown option "cylces" (did you mean "cycles"?)'),
    (dict(cycles=0), "cycles (solver.cycles): value 0 out of range"),
    (dict(solver="nope"), 'solver (solver.name): unknown value "nope"'),
    (dict(dt=-1.0), "dt: value -1 out of range"),
    (dict(depth=11, basis="octree"), "depth (octree.depth): value 11 out of range"),
    (dict(normalize_area="yes"), "normalize_area: expected true or false"),
    (dict(flow="cmcf", basis="octree", tracking="rebuilt"), "flow"),
    (dict(max_memory="lots"), "max_memory: expected a size"),
    (dict(config={"solver": {"cycels": 2}}), "solver.cycels: unknown key"),
])
def test_bad_options_raise_value_error_naming_the_key(options, message):
    with pytest.raises(ValueError) as e:
        mcfbench.flow(mesh="icosphere:level=2", steps=1, **options)
    assert message in str(e.value)
    assert str(e.value).startswith("mcfbench.flow: ")


def test_a_value_of_the_wrong_kind_raises_type_error_naming_the_key():
    with pytest.raises(TypeError, match="dt: expected a number"):
        mcfbench.flow(mesh="icosphere:level=2", dt=[1e-3])
    with pytest.raises(TypeError, match="config: expected a dict"):
        mcfbench.flow(mesh="icosphere:level=2", config=3)


def test_a_mesh_spec_that_cannot_be_loaded_raises_value_error_naming_it(tmp_path):
    with pytest.raises(ValueError, match="unknown generator 'nosuch'"):
        mcfbench.flow(mesh="nosuch:x=1")
    with pytest.raises(ValueError, match="no such file"):
        mcfbench.flow(mesh=str(tmp_path / "missing.off"))


def tetrahedron():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


def test_bad_arrays_raise_clear_exceptions():
    V, F = tetrahedron()

    def error(V, F, kind=ValueError):
        with pytest.raises(kind) as e:
            mcfbench.flow(V, F, steps=1)
        return str(e.value)

    assert "V: expected an n x 3 array" in error(V[:, :2], F)
    assert "got shape (4,)" in error(V[:, 0], F)
    assert "F: expected an m x 3 array" in error(V, F[:, :2])
    assert "F: expected integer vertex indices" in error(V, F.astype(float), TypeError)
    assert "V: expected real coordinates" in error(V.astype(complex), F, TypeError)
    bad = F.copy()
    bad[2, 1] = 7
    assert "arrays: face 2 references vertex 7 but the mesh has 4 vertices" in error(V, bad)
    bad[2, 1] = -1
    assert "face 2 references vertex -1" in error(V, bad)
    bad[2, 1] = 2**40
    assert "beyond the int32 range" in error(V, bad)
    bad = F.copy()
    bad[3] = [1, 1, 3]
    assert "face 3 repeats vertex 1" in error(V, bad)
    for value in (np.nan, np.inf):
        W = V.copy()
        W[2, 0] = value
        assert "arrays: vertex 2 has a non-finite" in error(W, F)
    # A fifth face on the edge (0, 1), which two faces have already.
    W = np.vstack([V, [[0.5, -1, 0.5]]])
    assert "non-manifold mesh: face 4" in error(W, np.vstack([F, [[0, 1, 4]]]))
    assert "give both V and F" in error(V, None)
    assert "named beside the mesh" in str(
        pytest.raises(ValueError, mcfbench.flow, V, F, mesh="icosphere:level=1").value)


def test_faces_of_mixed_orientation_are_reoriented_as_a_files_are():
    V, F = tetrahedron()
    F = F.copy()
    F[3] = F[3, ::-1]
    r = mcfbench.flow(V, F, steps=1, threads=1)
    assert r.result["mesh"]["reoriented_faces"] == 1
    assert (r.F[3] == [1, 2, 3]).all() or (r.F[3] == [2, 3, 1]).all() or (r.F[3] == [3, 1, 2]).all()


def test_help_lists_every_option_of_the_command_line():
    doc = mcfbench.flow.__doc__
    for o in mcfbench.flow_options():
        assert "    " + o["name"] + " (" in doc, o["name"]
    names = {o["name"] for o in mcfbench.flow_options()}
    assert {"mesh", "dt", "steps", "solver", "cycles", "normalize_area", "frozen"} <= names


def test_mesh_info_is_the_command_lines_report(mcfbench_binary):
    cli = json.loads(run_cli(mcfbench_binary, "mesh-info", "cgal:cow").stdout)
    assert mcfbench.mesh_info(mesh="cgal:cow") == cli
    V, F = tetrahedron()
    F = F.copy()
    F[3] = F[3, ::-1]
    report = mcfbench.mesh_info(V, F)
    assert report["spec"] == "arrays" and report["kind"] == "arrays"
    assert (report["vertices"], report["faces"], report["genus"]) == (4, 4, 0)
    assert report["reoriented_faces"] == 1 and "reoriented 1 of 4 faces" in report["notes"][0]
    assert report["bbox_max"] == [1.0, 1.0, 1.0]  # arrays keep their frame


def test_a_flow_started_inside_a_running_flow_is_refused():
    def callback(step, t, V):
        mcfbench.flow(mesh="icosphere:level=1", steps=1)

    with pytest.raises(ValueError, match="called from inside a running flow"):
        mcfbench.flow(mesh="icosphere:level=1", steps=2, callback=callback)
    # The lock was let go: the next flow runs.
    assert mcfbench.flow(mesh="icosphere:level=1", steps=1).result["status"] == "ok"
