"""mcfbench.run and mcfbench.results: a study with a solver written in Python beside CHOLMOD,
read back as a DataFrame; errors in a config and in a cell."""

import json

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla

import mcfbench

mcfbench.register_solver("study-splu", lambda A: sla.splu(sp.csc_matrix(A)).solve)


def study(tmp_path, solvers, name="python_solver"):
    config = tmp_path / (name + ".json")
    config.write_text(json.dumps({
        "name": name,
        "description": "CHOLMOD against a solver written in Python",
        "defaults": {"mesh": "icosphere:level=2", "flow": "mcf", "dt": 1e-3, "steps": 3,
                     "threads": 1},
        "axes": {"solver.name": solvers},
    }))
    return str(config)


def test_a_python_solver_joins_a_study_and_its_cells_read_back_as_a_dataframe(tmp_path, capfd):
    out = str(tmp_path / "results")
    assert mcfbench.run(study(tmp_path, ["cholmod", "study-splu"]), out) == out
    err = capfd.readouterr().err
    assert "[1/2] cell 0" in err and "[2/2] cell 1" in err  # run's progress lines
    df = mcfbench.results(out)
    assert len(df) == 2
    assert list(df["solver.name"]) == ["cholmod", "study-splu"]
    assert list(df["cell.index"]) == [0, 1]
    assert (df["status"] == "ok").all() and (df["stop.reason"] == "completed").all()
    assert (df["steps"] == 3).all() and (df["dt"] == 1e-3).all()
    assert (df["timing.step_median_seconds"] > 0).all()
    assert list(df["solver_name"]) == ["cholmod", "study-splu"]
    # A rerun finds both cells finished.
    mcfbench.run(study(tmp_path, ["cholmod", "study-splu"]), out)
    assert "2 skipped" in capfd.readouterr().out


def test_a_cell_whose_solver_raises_is_recorded_and_the_run_raises_after_the_others(tmp_path):
    def factory(A):
        raise ArithmeticError("no factor today")

    mcfbench.register_solver("study-raises", factory)
    out = str(tmp_path / "results")
    with pytest.raises(RuntimeError, match="a cell ended in an error"):
        mcfbench.run(study(tmp_path, ["study-raises", "cholmod"], "raises"), out)
    df = mcfbench.results(out).set_index("solver.name")
    assert df.loc["cholmod", "status"] == "ok"
    assert df.loc["study-raises", "status"] == "error"
    assert "no factor today" in df.loc["study-raises", "error"]


def test_bad_configs_and_folders_raise_value_error(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"name": "bad", "defaults": {"mesh": "icosphere:level=1",
                                                          "cycels": 2}}))
    with pytest.raises(ValueError, match="cycels"):
        mcfbench.run(str(bad), str(tmp_path / "out"))
    with pytest.raises(ValueError, match="no such folder"):
        mcfbench.results(str(tmp_path / "none"))
