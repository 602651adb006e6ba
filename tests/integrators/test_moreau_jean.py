"""Moreau–Jean against the event-driven reference and exact friction laws."""
import math

import numpy as np
import pytest

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import Line, PointOnLine
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.model.scene import Scene
from nonsmooth_rod.rod.simulation import simulate
from nonsmooth_rod.solvers import available_solvers

G = 9.81
REFERENCE = {case: simulate(RodProblem.paper(case)) for case in (1, 2, 3)}
EXACT_SOLVERS = [s for s in available_solvers() if not s.endswith("-relaxed")]


def _assert_matches_reference(run, ref, h):
    assert run.status == "ok", run.result.message
    assert [p.mode for p in run.phases] == [p.mode for p in ref.phases]
    for got, want in zip(run.phases, ref.phases):
        assert abs(got.t_start - want.t_start) <= 3 * h
        assert abs(got.t_end - want.t_end) <= 3 * h
    assert abs(run.impact["t"] - ref.impact["t"]) <= 3 * h


# The QP backends cost 100–1000× Lemke per step (docs/solvers.md): the suite checks them at
# h = 1e-3; benchmarks/bench_moreau_jean.py runs them at 1e-4 too.
SOLVER_STEPS = [(s, h) for s in EXACT_SOLVERS for h in ((1e-3, 1e-4) if s in ("lemke", "pgs", "enum") else (1e-3,))]
# The QP backends (osqp 1.3–1.9 s a case, clarabel 0.6–0.9 s) on case 2 only, the case with all
# three phases (stick, slip-, slip+); every other solver on all three cases.
SOLVER_CASES = [(s, h, c) for s, h in SOLVER_STEPS for c in ((2,) if s in ("osqp", "clarabel") else (1, 2, 3))]


@pytest.mark.parametrize("solver, h, case", SOLVER_CASES)
def test_paper_cases_every_solver_match_the_reference_within_3h(solver, case, h):
    _assert_matches_reference(simulate(RodProblem.paper(case), "moreau-jean", h=h, solver=solver),
                              REFERENCE[case], h)


def test_impact_time_is_interpolated_inside_the_step():
    """Ball B's gap crossing is located inside the step, not at the step's end."""
    h = 1e-3
    errors = [abs(simulate(RodProblem.paper(c), "moreau-jean", h=h).impact["t"] - REFERENCE[c].impact["t"])
              for c in (1, 2, 3)]
    assert np.median(errors) < 0.5 * h


def test_convergence_order_of_position_and_impact_time():
    ref = simulate(RodProblem.paper(2), output_dt=1e-4)
    k_ref = int(np.argmin(np.abs(ref.table["t"] - 0.3)))  # the table also holds event rows
    assert ref.table["t"][k_ref] == pytest.approx(0.3, abs=1e-12)
    steps = [1e-3, 1e-4, 1e-5]
    err_x, err_t = [], []
    for h in steps:
        run = simulate(RodProblem.paper(2), "moreau-jean", h=h)
        k = int(round(0.3 / h))
        err_x.append(abs(run.table["x_O"][k] - ref.table["x_O"][k_ref]))
        err_t.append(abs(run.impact["t"] - ref.impact["t"]))
    order_x = np.polyfit(np.log(steps), np.log(err_x), 1)[0]
    order_t = np.polyfit(np.log(steps), np.log(err_t), 1)[0]
    assert order_x >= 0.9, err_x
    assert order_t >= 0.9, err_t


@pytest.mark.parametrize("case", [1, 2, 3])
def test_energy_of_the_paper_cases_never_grows_with_e0_and_theta_half(case):
    # On these runs; in general a step may gain its O(h²) start work (test_bench_energy.py).
    p = RodProblem.paper(case)
    run = simulate(p, "moreau-jean", h=1e-3, t_end=0.6)
    scene = p.scene()
    tr = run.result.trajectory
    energy = np.array([scene.energy(q, v) for q, v in zip(tr.q, tr.v)])
    assert np.max(np.diff(energy)) <= 1e-9 * energy[0]
    assert energy[-1] < energy[0]


def test_frictionless_rod_keeps_its_centre_of_mass_abscissa():
    run = simulate(RodProblem.paper(None, mu_s=0.0, mu_d=0.0), "moreau-jean", h=1e-4)
    x_com = run.result.trajectory.q[:, 0]
    # no horizontal force: x_Γ constant up to round-off of the 3700 position updates (relative to
    # the body's size; measured 1e-16 m)
    assert np.max(np.abs(x_com - x_com[0])) < 1e-13 * run.problem.length


# --- blocks on inclines: two corner contacts, statically indeterminate when both stick -------

def _block_on_incline(alpha, mu_s, mu_d, width=0.2, height=0.1, mass=1.0):
    inertia = mass * (width**2 + height**2) / 12
    incline = Line((0.0, 0.0), alpha)
    law = ContactLaw.of(mu_s, mu_d)
    corners = [PointOnLine(0, (-width / 2, -height / 2), incline, law, "rear"),
               PointOnLine(0, (width / 2, -height / 2), incline, law, "front")]
    scene = Scene([RigidBody(mass, inertia, "block")], corners, gravity=G)
    t, n = incline.tangent, incline.normal
    q0 = np.array([n[0] * height / 2, n[1] * height / 2, alpha])
    return scene, q0, np.array(t), np.array(n)


@pytest.mark.parametrize("h", np.linspace(1e-3, 2e-3, 40))
def test_block_launched_up_an_incline_resticks_for_every_step_size(h):
    alpha, mu_s, mu_d, v0 = math.radians(25.0), 0.5, 0.3, 1.0
    scene, q0, t_dir, _ = _block_on_incline(alpha, mu_s, mu_d)
    t_stop = v0 / (G * (math.sin(alpha) + mu_d * math.cos(alpha)))
    res = MoreauJean(MoreauJeanOptions(h=float(h))).run(scene, q0, v0 * np.r_[t_dir, 0.0], t_stop + 0.3)
    assert res.status == "ok"
    speed = res.trajectory.v[:, :2] @ t_dir
    k_stop = int(np.argmax(speed <= 1e-12))
    assert abs(res.trajectory.t[k_stop] - t_stop) <= 2 * h
    after = slice(k_stop, None)
    assert np.max(np.abs(res.trajectory.v[after])) < 1e-12  # it stays: no slide back down
    assert np.ptp(res.trajectory.q[after, 0]) < 1e-12


def test_block_held_by_static_friction_does_not_creep():
    alpha = math.radians(20.0)
    scene, q0, _, _ = _block_on_incline(alpha, 0.5, 0.3)
    h = 1e-3
    res = MoreauJean(MoreauJeanOptions(h=h)).run(scene, q0, np.zeros(3), 1e5 * h)
    assert res.steps == 100_000
    assert np.max(np.abs(res.trajectory.q[-1] - q0)) < 1e-12
    assert set(res.trajectory.modes[1:].ravel()) == {"stick"}


def test_block_slides_with_the_dynamic_coefficient():
    alpha, mu_s, mu_d = math.radians(20.0), 0.3, 0.25
    scene, q0, t_dir, _ = _block_on_incline(alpha, mu_s, mu_d)
    h, t_end = 1e-3, 0.5
    res = MoreauJean(MoreauJeanOptions(h=h)).run(scene, q0, np.zeros(3), t_end)
    speed = res.trajectory.v[:, :2] @ t_dir
    accel = np.diff(speed) / h
    expected = -G * (math.sin(alpha) - mu_d * math.cos(alpha))  # down the slope: −t direction
    assert np.allclose(accel, expected, rtol=1e-6)
    assert set(res.trajectory.modes[1:].ravel()) == {"slip-"}


def test_blas_is_held_to_one_thread_from_the_limits_step_count_on(monkeypatch):
    """A run of BLAS_LIMIT_STEPS steps or more holds BLAS to one thread (_jit.one_blas_thread); a
    shorter one leaves it as it is (setting and restoring it cost more than its few LAPACK calls),
    and runs the same steps: the limit changes no result."""
    import contextlib

    import nonsmooth_rod as nr
    from nonsmooth_rod import _jit, toys
    from nonsmooth_rod.integrators import moreau_jean

    entered = []

    @contextlib.contextmanager
    def recorded():
        entered.append(True)
        yield

    monkeypatch.setattr(_jit, "one_blas_thread", recorded)
    toy = toys.BouncingBall()
    scene, (q0, v0) = toy.scene(), toy.initial_state()
    h, limit = 1e-3, moreau_jean.BLAS_LIMIT_STEPS
    short = nr.simulate(scene, q0, v0, (limit - 1) * h, h=h)
    assert not entered and short.steps == limit - 1
    long = nr.simulate(scene, q0, v0, limit * h, h=h)
    assert entered == [True] and long.steps == limit
    np.testing.assert_array_equal(long.q[:limit], short.q)
