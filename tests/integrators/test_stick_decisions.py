"""Break-aways of fixed-step Moreau–Jean confirmed by the smooth phase's prediction
(integrators/stick_decisions.py), against the event-driven reference: the rod at μs = max T/N ± δ
gets the reference's phases at h = 1e-3 down to δ = ±1e-6, a break-away far from grazing is the
step's own (the trajectory of the step's law alone), and scenes the hybrid method does not run
are left to the step's law."""
from __future__ import annotations

import functools

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.integrators import moreau_jean
from nonsmooth_rod.integrators.hybrid import Hybrid
from nonsmooth_rod.integrators.moreau_jean_records import Grid
from nonsmooth_rod.integrators.stick_decisions import PREDICTED_CONTACTS, stick_decisions
from nonsmooth_rod.model.packing import C_MU_D, C_MU_S
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.simulation import simulate as simulate_rod

H = 1e-3


def _peak() -> float:
    return rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max


@pytest.mark.parametrize("delta", [1e-6, -1e-6])
def test_grazing_rod_has_the_reference_phases_at_a_fixed_step(delta):
    """μs = max T/N ± 1e-6: the step's ratio overshoots the exact one by 0.22 h = 2.2e-4, so the
    step alone broke away at the peak for +1e-6 (the reference rolls through it) and 5 ms early
    for −1e-6. Confirmed by the smooth phase from the rod's exact start, the stick ends where the
    reference's does (the prediction locates it to ~1e-8 s) and every phase is the reference's."""
    problem = RodProblem.paper(None, mu_s=_peak() + delta, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    run = simulate_rod(problem, "moreau-jean", h=H)
    assert [p.mode for p in run.phases] == [p.mode for p in reference.phases]
    assert abs(run.phases[0].t_end - reference.phases[0].t_end) < 1e-6
    # the later boundaries are the step's own (a slip reversal, ball B's impact): within a few steps
    assert max(abs(a.t_end - b.t_end) for a, b in zip(run.phases, reference.phases)) < 3 * H
    assert run.result.stats["stick_predictions"] >= 1


def test_break_away_far_from_grazing_is_the_steps_own(monkeypatch):
    """μs = max T/N − 0.02: T/N crosses μs on its way up, at 0.064 s, far from the peak, and the
    step breaks away in the step holding the exact time: the break-away is kept, so the trajectory
    is the step's law's bit for bit (a run without the decisions); only its boundary is placed at
    the predicted time."""
    problem = RodProblem.paper(None, mu_s=_peak() - 0.02, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    run = simulate_rod(problem, "moreau-jean", h=H)
    monkeypatch.setattr(moreau_jean, "stick_decisions", lambda *args: None)
    alone = simulate_rod(problem, "moreau-jean", h=H)
    assert np.array_equal(run.result.q, alone.result.q) and np.array_equal(run.result.v, alone.result.v)
    assert [p.mode for p in run.phases] == [p.mode for p in reference.phases] == ["stick", "slip-", "slip+"]
    assert abs(run.phases[0].t_end - reference.phases[0].t_end) < 1e-6 < abs(alone.phases[0].t_end - reference.phases[0].t_end)
    assert run.result.stats["stick_predictions"] == 1 and alone.result.stats["stick_predictions"] == 0


def test_break_away_the_step_makes_late_is_moved_to_the_exact_one():
    """μs = max T/N + 0.02: the rod rolls through the peak and breaks away as T/N falls to −μs,
    at 0.2967 s; the step's state lags the exact one there by ~2 ms (the energy its projections
    take, first order), and the step alone broke away 3 steps late. The prediction from the
    rod's start moves it to the step holding the exact time (a change of the scheme's order)."""
    problem = RodProblem.paper(None, mu_s=_peak() + 0.02, mu_d=0.2)
    reference = simulate_rod(problem, "event-driven")
    run = simulate_rod(problem, "moreau-jean", h=H)
    assert [p.mode for p in run.phases] == [p.mode for p in reference.phases] == ["stick", "slip+"]
    assert abs(run.phases[0].t_end - reference.phases[0].t_end) < 1e-6
    sliding = np.flatnonzero(run.result.trajectory.modes[:, 0] == "slip+")[0]
    assert run.result.trajectory.t[sliding - 1] <= reference.phases[0].t_end + 2 * H


def test_packed_friction_is_restored_after_the_run():
    """The holds and releases change μs and μd in the packed table only while their steps run:
    the table is shared by later runs of the scene (integrators/scene_plans.py)."""
    problem = RodProblem.paper(None, mu_s=_peak() + 1e-6, mu_d=0.2)
    scene = problem.scene()
    q0, v0 = problem.initial_state()
    first = nr.simulate(scene, q0, v0, 0.3, "moreau-jean", h=H)
    again = nr.simulate(scene, q0, v0, 0.3, "moreau-jean", h=H)
    assert first.stats["stick_predictions"] >= 1
    assert np.array_equal(first.q, again.q)
    assert [c.law.friction.mu_s for c in scene.contacts] == [problem.mu_s] * 2


def _decisions(scene):
    model = moreau_jean._model(moreau_jean.pack_scene(scene))
    return stick_decisions(scene, model, Grid.of(H, 0.0, 0.1, None))


def test_scenes_the_hybrid_method_does_not_run_are_left_to_the_step():
    """Dominoes (their corners on each other: VertexOnEdge contacts) have no decisions, nor, from
    its first prediction on, a block on a shaken plate (a driven line): the step's law alone; the
    kinds checked first, before importing the hybrid method, are its own. The rod has them, on the
    run's packed table."""
    assert PREDICTED_CONTACTS == set(Hybrid.declares.contacts)
    assert _decisions(toys.Dominoes().scene()) is None
    shaken = toys.ShakenBlock().scene()
    decisions = _decisions(shaken)  # its contacts are the hybrid method's, its driven plate is not
    assert not decisions._predicts() and decisions.predictions == 0
    decisions = _decisions(RodProblem.paper().scene())
    assert decisions._predicts() and decisions.table[0, C_MU_S] > decisions.table[0, C_MU_D]


def test_stop_condition_during_a_hold_ends_on_the_held_trajectory():
    """A stop condition that holds while the rod is held through its T/N peak (δ = +1e-6, the
    step's break-away at 0.153 s taken back): the run ends at its first kept sample where it
    holds, on the very trajectory of the run without the condition, still sticking."""
    problem = RodProblem.paper(None, mu_s=_peak() + 1e-6, mu_d=0.2)
    scene = problem.scene()
    q0, v0 = problem.initial_state()
    full = nr.simulate(scene, q0, v0, 0.37, "moreau-jean", h=H)
    stopped = nr.simulate(scene, q0, v0, 0.37, "moreau-jean", h=H, stop=lambda t, q, v: t >= 0.2)
    assert stopped.status == "stopped" and stopped.t[-1] == pytest.approx(0.2, abs=H / 2)
    assert np.array_equal(stopped.q, full.q[: len(stopped.q)])
    assert [p.mode for p in stopped.phases["A"]] == ["stick"]


def test_a_scenes_later_runs_reuse_its_predictor_with_the_same_decisions():
    """The predicting Hybrid (its compiled mode solves set up) is given back to the scene's plan
    after a prediction and taken by the next run, which decides the same (the same trajectory and
    predicted boundary)."""
    from nonsmooth_rod.integrators.scene_plans import scene_plan

    problem = RodProblem.paper(None, mu_s=_peak() + 1e-6, mu_d=0.2)
    scene, (q0, v0) = problem.scene(), problem.initial_state()
    first = nr.simulate(scene, q0, v0, 0.3, "moreau-jean", h=H)
    plan = scene_plan(scene)
    assert plan.predicted is True and len(plan.predictors) == 1
    kept = plan.predictors[0]
    again = nr.simulate(scene, q0, v0, 0.3, "moreau-jean", h=H)
    assert plan.predictors == [kept] and again.stats["stick_predictions"] == first.stats["stick_predictions"] >= 1
    assert np.array_equal(first.q, again.q) and np.array_equal(first.v, again.v)
    assert [e.t for e in first.events] == [e.t for e in again.events]


def test_a_statically_indeterminate_stick_is_left_to_the_step(monkeypatch):
    """The pushed block sticks on two corners (four rows of A for three freedoms: singular at
    every state, a split the compiled mode solve does not choose): its break-away is not predicted
    (no mode solve, no projection), so the run is the step's law's bit for bit, each corner's
    onset within a step of the closed form t* = μs m g / rate."""
    block = toys.PushedBlock()
    scene, (q0, v0) = block.scene(), block.initial_state()
    run = nr.simulate(scene, q0, v0, 0.6, "moreau-jean", h=H)
    monkeypatch.setattr(moreau_jean, "stick_decisions", lambda *args: None)
    alone = nr.simulate(scene, q0, v0, 0.6, "moreau-jean", h=H)
    assert np.array_equal(run.q, alone.q) and np.array_equal(run.v, alone.v)
    assert run.stats["stick_predictions"] == 0
    onsets = [next(p.t_start for p in run.phases[c.name] if p.mode.startswith("slip")) for c in scene.contacts]
    assert max(abs(t - block.onset_time) for t in onsets) <= H


def test_contacts_declared_in_another_order_get_the_same_decisions():
    """The rod's balls declared B first: A, the one sticking, takes the records' first column
    (Window.columns: columns in the order contacts become candidates; B, in the air, has none),
    so the review maps columns to contacts. δ = +1e-6: the stick still ends where the
    reference's does, by the one prediction."""
    from nonsmooth_rod.model.scene import Scene

    problem = RodProblem.paper(None, mu_s=_peak() + 1e-6, mu_d=0.2)
    declared = problem.scene()
    scene, (q0, v0) = Scene(declared.bodies, declared.contacts[::-1], gravity=declared.gravity), problem.initial_state()
    reference = nr.simulate(scene, q0, v0, 0.38, "event-driven")
    run = nr.simulate(scene, q0, v0, 0.38, "moreau-jean", h=H)
    assert [c.name for c in scene.contacts] == ["B", "A"] and run.stats["stick_predictions"] == 1
    assert [p.mode for p in run.phases["A"]] == [p.mode for p in reference.phases["A"]] == ["stick", "slip+"]
    assert abs(run.phases["A"][0].t_end - reference.phases["A"][0].t_end) < 1e-6


_REFUSED: list = []


def test_a_run_whose_steps_go_interpreted_predicts_interpreted_with_the_same_decisions(monkeypatch):
    """A cold cache runs the steps interpreted while the engine compiles in the background; the
    run's predictions then run the hybrid's plain-Python twins (compiling them would make the
    user wait ~5 s: issue 25's first run), and decide as the compiled ones: the same source."""
    from nonsmooth_rod import _jit
    from nonsmooth_rod.integrators import hybrid
    from nonsmooth_rod.model import dynamics

    if not _jit.ENABLED:
        pytest.skip("numba not installed: every kernel is interpreted")
    problem = RodProblem.paper(2)
    q0, v0 = problem.initial_state()
    compiled = nr.simulate(problem.scene(), q0, v0, 0.5, h=1e-3, solver="lemke")

    class CompiledRefused:  # a kernel called compiled fails; its twin (py_func) runs
        def __init__(self, kernel):
            self.py_func = kernel.py_func

        def __call__(self, *args):
            raise AssertionError(f"{self.py_func.__name__} called compiled")

    for module, name in ((hybrid, "screened_steps_into"), (hybrid, "hermite_into"),
                         (dynamics, "mode_rates_into"), (dynamics, "runge_kutta_into")):
        _REFUSED.append(CompiledRefused(getattr(module, name)))  # (kept: twins are cached by id)
        monkeypatch.setattr(module, name, _REFUSED[-1])
    hybrid._mode_system_twins.cache_clear()
    monkeypatch.setattr(hybrid, "_mode_system_twins", functools.cache(hybrid._mode_system_twins.__wrapped__))
    plain = nr.simulate(problem.scene(), q0, v0, 0.5, h=1e-3, solver="lemke", fast=False)
    assert plain.stats["stick_predictions"] == compiled.stats["stick_predictions"] == 2
    assert [(e.kind, e.contact) for e in plain.events] == [(e.kind, e.contact) for e in compiled.events]
    assert np.allclose([e.t for e in plain.events], [e.t for e in compiled.events], rtol=0, atol=1e-12)
