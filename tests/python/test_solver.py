"""Solvers written in Python (mcfbench.register_solver) in flows: a direct and an iterative one
against CHOLMOD's flow, their records, their errors."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla

import mcfbench

# cMCF at unit area (the README's flow), which keeps the cow's system well conditioned: MCF pinches
# its thin parts within a few steps, where any two exact solvers part by far more than 1e-8.
MESH = dict(mesh="cgal:cow", flow="cmcf", normalize_area=True, steps=5, dt=1e-3, threads=1)


def splu_factory(A):
    assert sp.issparse(A) and A.shape[0] == A.shape[1]
    return sla.splu(sp.csc_matrix(A)).solve


def cg_factory(A):
    def solve(B, X0):
        # Relative residual 1e-13 per column, from the flow's prediction.
        return np.column_stack([sla.cg(A, B[:, i], x0=X0[:, i], tol=1e-13, atol=0)[0]
                                for i in range(B.shape[1])])
    return solve


mcfbench.register_solver("test-splu", splu_factory, help="SuperLU (scipy)")
mcfbench.register_solver("test-cg", cg_factory, iterative=True)


@pytest.fixture(scope="module")
def cholmod():
    return mcfbench.flow(**MESH)


@pytest.mark.parametrize("solver", ["test-splu", "test-cg"])
def test_a_python_solver_gives_cholmods_flow(cholmod, solver):
    r = mcfbench.flow(solver=solver, **MESH)
    assert r.result["status"] == "ok" and r.result["solver_name"] == solver
    # Both solve each step's system to about 1e-13 relative residual or below; five steps of the
    # unit-area cow stay within 1e-8 of CHOLMOD's positions (measured: 1e-14 by SuperLU).
    assert np.abs(r.V - cholmod.V).max() < 1e-8
    for step in r.result["steps"]:
        assert step["solver"]["status"] == "converged"
        assert step["solver"]["relative_residual"] < 1e-10
        assert step["seconds"]["solve"] > 0  # timed as a built-in solver's solves are


def test_the_factory_is_called_once_per_new_matrix():
    calls = []

    def factory(A):
        calls.append(A.copy())
        return sla.factorized(sp.csc_matrix(A))

    mcfbench.register_solver("test-counted", factory)
    mcfbench.flow(mesh="icosphere:level=2", flow="mcf", steps=3, threads=1, solver="test-counted")
    assert len(calls) == 3  # MCF: a new mass and stiffness every step
    calls.clear()
    mcfbench.flow(mesh="icosphere:level=2", flow="heat", steps=3, threads=1, solver="test-counted")
    assert len(calls) == 1  # heat flow keeps its system
    A = calls[0]
    assert abs(A - A.T).max() == 0  # symmetric, both triangles stored


def test_an_exception_in_a_python_solver_reaches_the_caller_unchanged():
    def factory(A):
        def solve(B):
            raise ZeroDivisionError("inside the solve")
        return solve

    mcfbench.register_solver("test-raises", factory)
    with pytest.raises(ZeroDivisionError, match="inside the solve"):
        mcfbench.flow(mesh="icosphere:level=2", steps=2, solver="test-raises")


def test_a_solution_of_the_wrong_shape_raises_value_error_naming_the_solver():
    mcfbench.register_solver("test-shape", lambda A: (lambda B: B[:, :2]))
    with pytest.raises(ValueError, match="solver test-shape: solve returned"):
        mcfbench.flow(mesh="icosphere:level=2", steps=2, solver="test-shape")


def test_a_non_finite_solution_ends_the_flow_as_singular():
    mcfbench.register_solver("test-nan", lambda A: (lambda B: B * np.nan))
    r = mcfbench.flow(mesh="icosphere:level=2", steps=2, solver="test-nan")
    assert r.result["status"] == "singular"
    assert r.result["stop"]["step"] == 1
    assert "numerical_issue" in r.result["stop"]["reason"]


def test_registering_again_replaces_and_built_in_names_are_refused():
    mcfbench.register_solver("test-again", lambda A: (lambda B: B * np.nan))
    mcfbench.register_solver("test-again", splu_factory)
    assert mcfbench.flow(mesh="icosphere:level=2", steps=1, solver="test-again").result[
        "status"] == "ok"
    with pytest.raises(ValueError, match="built-in solver"):
        mcfbench.register_solver("cholmod", splu_factory)
    with pytest.raises(TypeError):
        mcfbench.register_solver("test-not-callable", 3)
