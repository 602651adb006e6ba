"""Every public solver entry refuses non-finite or malformed data with the project's InputError
(issue 17: NaN/inf used to come back as a "solved" NaN, ±inf from pgs, numpy's argmin error from enum)."""
from __future__ import annotations

import numpy as np
import pytest

from nonsmooth_rod.solvers import available_solvers, solve
from nonsmooth_rod.solvers.gauss_seidel import projected_gauss_seidel
from nonsmooth_rod.solvers.lemke import lemke
from nonsmooth_rod.solvers.problem import PlanarFrictionProblem
from nonsmooth_rod.validation import InputError
from solver_cases import block_on_incline

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def corrupted(argument, bad):
    problem = block_on_incline(0.3, 0.5)
    data = {name: getattr(problem, name).copy() for name in ("W", "q", "lo", "hi")}
    data[argument].flat[-1] = bad
    return data


@pytest.mark.parametrize("argument", ["W", "q", "lo", "hi"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_step_problem_with_non_finite_data_is_refused(argument, bad):
    """Validated where the problem is made, so no solver (solve(), lemke_friction, pgs, enum,
    the QP ones: all take a PlanarFrictionProblem) ever sees it."""
    with pytest.raises(InputError, match=rf"^{argument} must be finite, got {bad!r} at index"):
        PlanarFrictionProblem(**corrupted(argument, bad))


def test_inconsistent_shapes_are_input_errors():
    with pytest.raises(InputError, match="inconsistent problem shapes"):
        PlanarFrictionProblem(np.eye(4), np.ones(4), [-0.5], [0.5])
    with pytest.raises(InputError, match="must contain 0"):
        PlanarFrictionProblem(np.eye(2), np.ones(2), [0.1], [0.5])


@pytest.mark.parametrize("M, q, name", [
    ([[np.nan]], [-1.0], "M"),
    ([[1.0]], [np.inf], "q"),
])
def test_general_lemke_refuses_non_finite_data(M, q, name):
    with pytest.raises(InputError, match=rf"lemke: {name} must be finite"):
        lemke(M, q)


def test_pgs_refuses_a_non_finite_warm_start():
    with pytest.raises(InputError, match=r"pgs: p0 must be finite, got nan at index 1"):
        projected_gauss_seidel(block_on_incline(0.3, 0.5), p0=[0.0, np.nan, 0.0, 0.0])


def test_unknown_solver_is_an_input_error_listing_the_choices():
    problem = block_on_incline(0.3, 0.5)
    for name in ("x", "", None, 3):
        with pytest.raises(InputError, match=r"unknown solver .*; choose from: lemke, pgs, enum"):
            solve(problem, name)
    with pytest.raises(InputError, match="problem must be a PlanarFrictionProblem"):
        solve({"W": problem.W}, "lemke")


@pytest.mark.parametrize("name", available_solvers())
def test_every_solver_still_solves_finite_data(name):
    problem = block_on_incline(0.6, 0.5)
    solution = solve(problem, name)
    assert np.all(np.isfinite(solution.p)) and solution.info["states"] == ["slip+", "slip+"]


def test_problem_keeps_its_own_validated_copies():
    data = corrupted("q", 0.0)
    problem = PlanarFrictionProblem(**data)
    data["q"][0] = np.nan  # the caller reuses its array: the problem is unaffected
    assert np.all(np.isfinite(problem.q))
    with pytest.raises(InputError, match="W must be an array of numbers"):
        PlanarFrictionProblem("W", data["q"], data["lo"], data["hi"])
