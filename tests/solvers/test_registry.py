"""The one table of solvers (solvers/registry.py): every name it lists is accepted wherever a
solver is chosen — nr.simulate, scene files, the command line — and solves; a name it does not
list is refused in one line naming the field and listing the table's names."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.cli import main
from nonsmooth_rod.solvers import solve
from nonsmooth_rod.solvers.kernels import KERNEL_NO_CONVERGENCE, KERNEL_SOLVED, solve_interval
from nonsmooth_rod.solvers.registry import (BLOCK_SPARSE_CODES, EXACT_SOLVERS, SOLVER_CODES, SOLVERS,
                                            available_solvers, check_solver_options, installed)
from nonsmooth_rod.toys import BouncingBall
from nonsmooth_rod.validation import InputError
from solver_cases import block_on_incline

SCENE = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "bouncing_ball.toml"


def _resting_ball():
    """The bouncing ball's scene with the ball resting on the floor (its lowest point at y = 0)."""
    toy = BouncingBall()
    q0, v0 = toy.initial_state()
    q0 = np.array(q0, dtype=float)
    q0[1] = toy.radius
    return toy.scene(), q0, np.zeros_like(q0)


def _refusal(name: str, field: str = "solver") -> str:
    return f"unknown {field} {name!r}; choose from: {', '.join(available_solvers())}"


def test_the_table_derives_codes_names_and_layouts():
    codes = [s.code for s in SOLVERS if s.code is not None]
    assert sorted(codes) == list(range(len(codes)))  # the compiled loop indexes per-code facts
    assert EXACT_SOLVERS == tuple(name for name, _ in sorted(SOLVER_CODES.items(), key=lambda item: item[1]))
    assert all((s.code is not None) == (s.kind == "exact") for s in SOLVERS)
    assert BLOCK_SPARSE_CODES == tuple(s.block_sparse for s in sorted(
        (s for s in SOLVERS if s.code is not None), key=lambda s: s.code))
    assert available_solvers()[:len(EXACT_SOLVERS)] == list(EXACT_SOLVERS)
    assert [s.name for s in installed()] == available_solvers()


@pytest.mark.parametrize("name", EXACT_SOLVERS)
def test_every_compiled_code_dispatches_to_its_solver(name):
    """solve_interval(code) gives the impulses solve(problem, name) gives: the compiled
    dispatch has a branch for every code of the table, and it is that solver's."""
    problem = block_on_incline(0.6, 0.5)  # both contacts slide: one exact answer
    p, u = np.zeros(problem.q.shape[0]), np.zeros(problem.q.shape[0])
    status, iterations, _ = solve_interval(SOLVER_CODES[name], problem.W, problem.q, problem.lo, problem.hi, p, u,
                                           0.0, 0)
    assert status == KERNEL_SOLVED
    reference = solve(problem, name)
    # the solvers' own counts differ here (Lemke 3 pivots, pgs 4 sweeps, enum 16 modes)
    assert iterations == reference.iterations
    np.testing.assert_allclose(p, reference.p, rtol=0, atol=1e-9 * np.max(np.abs(reference.p)))
    np.testing.assert_allclose(u, problem.W @ p + problem.q, rtol=0, atol=1e-9 * np.max(np.abs(problem.q)))


def test_a_code_beyond_the_table_solves_nothing():
    problem = block_on_incline(0.6, 0.5)
    p, u = np.ones(problem.q.shape[0]), np.zeros(problem.q.shape[0])
    status, _, residual = solve_interval(len(SOLVER_CODES), problem.W, problem.q, problem.lo, problem.hi, p, u,
                                         0.0, 0)
    assert status == KERNEL_NO_CONVERGENCE and residual == np.inf
    assert np.all(p == 0.0) and np.array_equal(u, problem.q)


@pytest.mark.parametrize("name", available_solvers())
def test_every_solver_of_the_table_holds_a_resting_ball_through_nr_simulate(name):
    """Accepted by nr.simulate and solving: a ball resting on the floor stays at rest (without the
    floor it would fall g t²/2 = 2e-5 m in these 2 ms) under each solver."""
    scene, q0, v0 = _resting_ball()
    result = nr.simulate(scene, q0, v0, 0.002, "moreau-jean", h=1e-3, solver=name)
    assert result.status == "ok", result.message
    assert result.stats["solver"] == name
    tolerance = 1e-6 if name not in EXACT_SOLVERS else 1e-12  # QP backends: their own tolerances
    assert np.max(np.abs(result.q[:, 1] - q0[1])) <= tolerance


@pytest.mark.parametrize("name", available_solvers())
def test_every_solver_of_the_table_is_accepted_by_scene_files(name):
    scene_file = nr.load_scene(SCENE, overrides=[f"simulation.moreau-jean.solver={name}"])
    assert scene_file.options["solver"] == name


@pytest.mark.parametrize("name", EXACT_SOLVERS + tuple(n for n in available_solvers() if n.endswith("-relaxed"))[:1])
def test_every_solver_of_the_table_is_accepted_by_the_command_line(name, tmp_path, capsys):
    code = main(["simulate", "--method", "moreau-jean", "--solver", name, "--t-end", "0.003", "--h", "1e-3",
                 "--no-plot", "--quiet", "--out", str(tmp_path)])
    assert code == 0, capsys.readouterr().err
    assert json.loads((tmp_path / "summary.json").read_text())["settings"]["solver"] == name


def test_an_unknown_solver_is_refused_in_one_line_naming_the_field():
    scene, q0, v0 = _resting_ball()
    with pytest.raises(InputError) as error:
        nr.simulate(scene, q0, v0, 0.002, "moreau-jean", solver="nope")
    assert str(error.value) == _refusal("nope")
    with pytest.raises(InputError) as error:
        nr.simulate(scene, q0, v0, 0.002, "event-driven", impact_solver="nope")
    assert str(error.value) == _refusal("nope", "impact_solver")
    with pytest.raises(InputError) as error:
        nr.load_scene(SCENE, overrides=["simulation.moreau-jean.solver=nope"])
    assert str(error.value).endswith(f"simulation: {_refusal('nope')}") and "\n" not in str(error.value)


def test_the_command_line_refuses_an_unknown_solver_with_exit_2(tmp_path, capsys):
    code = main(["simulate", "--method", "moreau-jean", "--solver", "nope", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip().splitlines() == [f"nonsmooth-rod: error: {_refusal('nope', '--solver')}"]
    code = main(["run", str(SCENE), "--set", "simulation.moreau-jean.solver=nope", "--out", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and _refusal("nope") in err


def test_solver_options_are_checked_against_the_row():
    assert check_solver_options("lemke", {"tol": 1e-10, "max_iter": 50}) == {"tol": 1e-10, "max_iter": 50}
    with pytest.raises(InputError, match=r"solver_options: unknown setting 'max_iter' for solver 'enum'; "
                                         r"it takes: tol$"):
        check_solver_options("enum", {"max_iter": 3})
    with pytest.raises(InputError, match=r"solver_options\.tol"):
        check_solver_options("pgs", {"tol": 2.0})
    qp = next((n for n in available_solvers() if n not in EXACT_SOLVERS and not n.endswith("-relaxed")), None)
    if qp is None:
        pytest.skip("no QP backend installed")
    assert check_solver_options(qp, {"tol": 1e-8, "verbose": False}) == {"tol": 1e-8, "verbose": False}
