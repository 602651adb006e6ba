"""The solve() entry point, solver names, shared residual and state classification."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings

import nonsmooth_rod.solvers as solvers
from nonsmooth_rod.solvers import available_solvers, solve
from nonsmooth_rod.solvers._common import velocities_and_residual
from nonsmooth_rod.solvers.problem import (
    ContactSolution,
    PlanarFrictionProblem,
    complementarity_residual,
    contact_states,
    residual_scale,
)
from solver_cases import block_on_incline, friction_steps

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def test_available_solvers_lists_exact_then_qp_backends():
    names = available_solvers()
    assert names[:3] == ["lemke", "pgs", "enum"]
    qpsolvers = pytest.importorskip("qpsolvers")
    for backend in qpsolvers.available_solvers:
        assert backend in names and backend + "-relaxed" in names
    assert {"osqp", "osqp-relaxed", "clarabel", "clarabel-relaxed"} <= set(names)


def test_unknown_solver_lists_choices():
    problem = block_on_incline(0.3, 0.5)
    with pytest.raises(ValueError, match=r"unknown solver 'x'; choose from: lemke, pgs, enum"):
        solve(problem, "x")
    with pytest.raises(ValueError, match="unknown solver 'lemke-relaxed'"):
        solve(problem, "lemke-relaxed")


def test_without_qpsolvers_the_exact_solvers_remain(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_qpsolvers(name, *args, **kwargs):
        if name == "qpsolvers":
            raise ImportError("qpsolvers hidden for this test")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_qpsolvers)
    from nonsmooth_rod.solvers import qp

    monkeypatch.setattr(qp, "_BACKENDS", None)  # probed once per process: probe again without qpsolvers
    assert available_solvers() == ["lemke", "pgs", "enum"]
    with pytest.raises(ValueError, match="choose from: lemke, pgs, enum$"):
        solve(block_on_incline(0.3, 0.5), "osqp")


@pytest.mark.parametrize("name", ["lemke", "pgs", "enum", "osqp", "clarabel", "osqp-relaxed"])
def test_solution_fields(name):
    if name not in available_solvers():
        pytest.skip(f"{name} not installed")
    problem = block_on_incline(0.6, 0.5)
    solution = solve(problem, name)
    assert isinstance(solution, ContactSolution) and solution.solver == name
    assert solution.p.shape == solution.u.shape == (4,)
    assert solution.info["states"] == ["slip+", "slip+"]
    assert solution.iterations >= 1


@settings(max_examples=100, deadline=None, derandomize=True)
@given(problem=friction_steps())
def test_fast_residual_equals_common_residual(problem):
    p = np.random.default_rng(0).normal(size=problem.q.shape)
    u, residual = velocities_and_residual(
        problem.W.tolist(), problem.q.tolist(), problem.lo.tolist(), problem.hi.tolist(), p.tolist()
    )
    scale = residual_scale(problem, p, u)  # the problem's scale: a few hundred ulps of it
    np.testing.assert_allclose(u, problem.W @ p + problem.q, rtol=0, atol=500 * np.finfo(float).eps * scale)
    assert residual == pytest.approx(complementarity_residual(problem, p), rel=1e-12,
                                     abs=500 * np.finfo(float).eps * scale)


def test_contact_states_classification():
    problem = PlanarFrictionProblem.coulomb(np.eye(8), np.ones(8), np.full(4, 0.5))
    p = np.array([0.0, 0.0, 1.0, 0.2, 1.0, -0.5, 1.0, 0.5])
    u = np.array([3.0, 2.0, 0.0, 1e-14, 0.0, 2.0, 0.0, -2.0])
    assert contact_states(problem, p, u) == ["open", "stick", "slip+", "slip-"]


def test_package_imports_without_touching_qpsolvers():
    assert "tresca_fixed_point" not in vars(solvers)


def test_everything_runs_without_numba_and_qpsolvers():
    """Both are optional: block their import in a fresh interpreter and solve with each
    remaining solver (Lemke then runs its plain-Python kernel)."""
    import subprocess
    import sys

    code = """
import sys
sys.modules["numba"] = None
sys.modules["qpsolvers"] = None
import numpy as np
from nonsmooth_rod.solvers import available_solvers, solve
from nonsmooth_rod.solvers.lemke import HAVE_NUMBA
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem
assert not HAVE_NUMBA
assert available_solvers() == ["lemke", "pgs", "enum"], available_solvers()
problem = PlanarFrictionProblem.coulomb(np.array([[2.0, 0.3], [0.3, 1.0]]), [-1.0, 2.0], 0.5)
solutions = [solve(problem, name) for name in available_solvers()]
assert all(np.allclose(s.p, solutions[0].p, atol=1e-12) for s in solutions)
print("ok", solutions[0].info["states"])
"""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok ['slip+']"


def test_the_qp_backends_are_probed_once_per_process(monkeypatch):
    """A missing qpsolvers is not imported again on every call (Python does not cache a failed
    import: ~60 µs a call, issue 25)."""
    import builtins

    from nonsmooth_rod.solvers import qp

    monkeypatch.setattr(qp, "_BACKENDS", None)
    tries = []
    real_import = builtins.__import__

    def counting(name, *args, **kwargs):
        if name == "qpsolvers":
            tries.append(name)
            raise ImportError("qpsolvers hidden for this test")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", counting)
    for _ in range(3):
        assert available_solvers() == ["lemke", "pgs", "enum"]
    assert tries == ["qpsolvers"]
