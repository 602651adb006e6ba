"""How a Moreau–Jean run proceeds and what it keeps: it ends exactly at t_end, thins while it runs,
tries stop conditions while it runs, and a restart from its end state continues bit for bit."""
import math
import time
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.scenefile import load_scene
from nonsmooth_rod.toys import stacks

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
SOLVERS = ("lemke", "pgs", "enum")


def sliding_ladder():
    """examples/scenes/ladder.toml with floor μs 0.2, μd 0.1: it slides (issue 22's case)."""
    sf = load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2", "contacts.foot.law.mu_d=0.1"])
    return sf.scene, sf.q0, sf.v0, 0.3


def belt():
    toy = toys.BeltOscillator()
    return toy.scene(), *toy.initial_state(), 1.2


def rod():
    p = RodProblem.paper(2)
    return p.scene(), *p.initial_state(), 0.36


def ball_row():
    scene, q0, v0 = stacks.ball_row(2)  # 3 contacts: within enum's 4
    return scene, q0, v0, 0.2


def clipped(phases, t_from):
    return {c: [(p.mode, max(p.t_start, t_from), p.t_end) for p in ps if p.t_end > t_from] for c, ps in phases.items()}


def assert_same_continuation(full, again, t_half):
    n = len(again.t)
    for name in ("t", "q", "v", "normal_force", "tangential_force"):
        np.testing.assert_array_equal(getattr(again, name), getattr(full, name)[-n:], err_msg=name)
    assert again.modes.tolist() == full.modes[-n:].tolist()
    later = [i for i in full.impacts if i.t >= t_half]
    assert [(i.t, i.contact) for i in again.impacts] == [(i.t, i.contact) for i in later]
    for a, b in zip(again.impacts, later):
        for name in ("q", "v_before", "v_after", "normal_impulse", "tangential_impulse"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert clipped(again.phases, t_half) == clipped(full.phases, t_half)
    assert [(e.t, e.kind, e.contact) for e in again.events] == \
        [(e.t, e.kind, e.contact) for e in full.events if e.t >= t_half]


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("make", [sliding_ladder, belt, rod, ball_row])
def test_a_restart_at_half_time_continues_bit_for_bit(make, solver):
    scene, q0, v0, t_end = make()
    h = 1e-3
    full = nr.simulate(scene, q0, v0, t_end, h=h, solver=solver)
    half = nr.simulate(scene, q0, v0, t_end / 2, h=h, solver=solver)
    assert full.success and half.success, (full.message, half.message)
    again = half.restart(t_end=t_end)
    assert again.t[0] == half.t[-1] and again.t[-1] == t_end
    assert_same_continuation(full, again, half.t[-1])
    assert len(full.events) > 0 or make is sliding_ladder  # something happens after the restart point


def test_a_loaded_result_restarts_bit_for_bit_too(tmp_path):
    scene, q0, v0, t_end = sliding_ladder()
    sf = load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2", "contacts.foot.law.mu_d=0.1"])
    full = nr.simulate(scene, q0, v0, t_end, **sf.options)
    half = nr.simulate_scene(load_scene(SCENES / "ladder.toml", ["contacts.foot.law.mu_s=0.2",
                                                                 "contacts.foot.law.mu_d=0.1", "simulation.t_end=0.15"]))
    half.save(tmp_path)
    again = nr.load(tmp_path).restart(t_end=t_end)
    assert_same_continuation(full, again, 0.15)
    # from (q, v) alone the contact memory is lost: the end differs (by ~7e-7 m, issue 22)
    qv_only = nr.simulate(scene, half.q[-1], half.v[-1], t_end, t0=0.15, **sf.options)
    assert not np.array_equal(qv_only.q[-1], full.q[-1])


def test_a_run_ends_exactly_at_t_end_and_a_step_longer_than_the_run_is_shortened():
    ball = toys.BouncingBall()
    scene, (q0, v0) = ball.scene(), ball.initial_state()
    g, y0 = 9.81, q0[1]
    one = nr.simulate(scene, q0, v0, 0.1, h=10.0)  # issue 29: reported t_end = 1 s at t = 10 s, y = −489 m
    assert one.t.tolist() == [0.0, 0.1] and one.steps == 1
    # one step of 0.1 s from rest: v = −g 0.1, y = y0 + 0.1 (0 + v)/2 (θ = ½), no contact reached
    assert one.v[-1, 1] == pytest.approx(-g * 0.1, rel=1e-12)
    assert one.q[-1, 1] == pytest.approx(y0 - g * 0.1 ** 2 / 2, rel=1e-12)
    odd = nr.simulate(scene, q0, v0, 0.0105, h=1e-3)  # 10 steps and a half
    assert odd.t[-1] == 0.0105 and odd.steps == 11 and odd.t[-2] == pytest.approx(0.010, abs=1e-15)
    assert odd.v[-1, 1] == pytest.approx(-g * 0.0105, rel=1e-12)  # free fall: exact at any step
    assert odd.q[-1, 1] == pytest.approx(y0 - g * 0.0105 ** 2 / 2, rel=1e-12)
    for method, options in (("event-driven", {}), ("regularized", {})):
        other = nr.simulate(scene, q0, v0, 0.0105, method=method, **options)
        assert other.t[-1] == pytest.approx(0.0105, abs=1e-15)
        assert other.q[-1, 1] == pytest.approx(y0 - g * 0.0105 ** 2 / 2, rel=1e-9)


def test_save_every_thins_during_the_run_and_keeps_events_and_phases_exact():
    scene, q0, v0, t_end = belt()
    every = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    thin = nr.simulate(scene, q0, v0, t_end, h=1e-3, save_every=0.05)
    assert len(thin.t) == 25 and thin.t[-1] == t_end  # 0, 0.05, …, 1.2
    rows = np.searchsorted(every.t, thin.t)
    np.testing.assert_array_equal(thin.q, every.q[rows])
    assert thin.modes.tolist() == every.modes[rows].tolist()
    assert [(e.t, e.kind) for e in thin.events] == [(e.t, e.kind) for e in every.events]
    assert clipped(thin.phases, 0.0) == clipped(every.phases, 0.0)
    np.testing.assert_array_equal(thin.end_state.q, every.end_state.q)


def test_a_stop_condition_ends_the_run_where_it_first_holds_without_running_on():
    ball = toys.BouncingBall(restitution=0.99)  # bounces past t_end (Zeno at 90 s): the run never comes to rest
    scene, (q0, v0) = ball.scene(), ball.initial_state()
    t_end, h = 40.0, 1e-4
    t_hold = 0.05 * t_end
    full_cpu = nr.simulate(scene, q0, v0, t_end, h=h, save_every=0.1).cpu_time_s
    stopped = nr.simulate(scene, q0, v0, t_end, h=h, save_every=0.1, stop=lambda t, q, v: t >= t_hold)
    assert stopped.status == "stopped" and stopped.t[-1] == pytest.approx(t_hold, abs=1e-9)
    assert stopped.steps == round(t_hold / h)
    assert stopped.cpu_time_s <= 0.25 * full_cpu  # ~0.08 measured (benchmarks/bench_memory.py --stop)
    # its end state is the state at the stop: a restart goes on as the unstopped run
    again = nr.simulate(scene, stopped.q[-1], stopped.v[-1], 2.5, h=h, save_every=0.1,
                        t0=stopped.t[-1], resume=stopped.end_state)
    reference = nr.simulate(scene, q0, v0, 2.5, h=h, save_every=0.1)
    np.testing.assert_array_equal(again.q[-1], reference.q[-1])


@pytest.mark.parametrize("make", [belt, rod])
def test_small_windows_give_the_very_same_run(make, monkeypatch):
    from nonsmooth_rod.integrators import moreau_jean

    scene, q0, v0, t_end = make()
    whole = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    monkeypatch.setattr(moreau_jean, "MAX_CHUNK", 7)  # windows of 7 steps: slides between phase boundaries
    windows = nr.simulate(scene, q0, v0, t_end, h=1e-3)
    assert_same_continuation(whole, windows, 0.0)
    assert len(whole.events) >= 2


# --- records only for the contacts that come near (moreau_jean_loop.new_records) ----------------
BOX_W, BOX_H = 0.4, 0.3


def box_tower(n: int, found: bool):
    """(scene, q0) of n boxes stacked on a floor (benchmarks/bench_shapes.py's tower): every pair of
    shapes' candidate contacts found (32 a pair of boxes), or the 2n that touch declared by hand."""
    bodies = [nr.RigidBody(1.0, (BOX_W ** 2 + BOX_H ** 2) / 12.0, name=f"box{k}") for k in range(n)]
    law, floor, box = nr.ContactLaw.of(0.5, 0.4), nr.Line(), nr.Polygon.rectangle(BOX_W, BOX_H)
    if found:
        contacts = nr.find_contacts(bodies, {b.name: box for b in bodies}, {"floor": floor}, nr.PairLaws(default=law))
    else:
        contacts = [nr.PointOnLine(0, box.vertices[i], floor, law, name=f"box0.v{i}/floor") for i in (0, 1)]
        contacts += [nr.VertexOnEdge(k, box.vertices[i], k - 1, *box.edge(2), cone=box.cone(i), law=law,
                                     name=f"box{k}.v{i}/box{k - 1}.e2") for k in range(1, n) for i in (0, 1)]
    q0 = np.zeros(3 * n)
    q0[1::3] = BOX_H / 2 + BOX_H * np.arange(n)
    return nr.Scene(bodies, contacts), q0


def windows_of_runs(monkeypatch):
    """The windows the runs make from now on (moreau_jean._window wrapped), each with the records it
    started with (`window.first_out`: lent or new; widening replaces `window.out`)."""
    from nonsmooth_rod.integrators import moreau_jean

    made, make = [], moreau_jean._window

    def window(*args):
        made.append(make(*args))
        made[-1].first_out = made[-1].out
        return made[-1]

    monkeypatch.setattr(moreau_jean, "_window", window)
    return made


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype == object:
        return a.shape == b.shape and np.array_equal(a, b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def assert_same_run(got, want):
    """The same run bit for bit: samples, modes, phases, events, impacts, end state."""
    for name in ("t", "q", "v", "normal_force", "tangential_force", "modes"):
        assert same_bits(getattr(got, name), getattr(want, name)), name
    assert got.phases == want.phases and got.events == want.events
    assert len(got.impacts) == len(want.impacts)
    for a, b in zip(got.impacts, want.impacts):
        assert (a.t, a.contact) == (b.t, b.contact)
        for name in ("q", "v_before", "v_after", "normal_impulse", "tangential_impulse"):
            assert same_bits(getattr(a, name), getattr(b, name)), name
    assert (got.end_state is None) == (want.end_state is None)
    if want.end_state is not None:
        assert got.end_state.as_dict() == want.end_state.as_dict()
        assert same_bits(got.end_state.slip, want.end_state.slip)  # (-0.0 is not 0.0)
    assert (got.status, got.message, got.steps) == (want.status, want.message, want.steps)


def test_found_contacts_that_never_come_near_have_no_records_yet_report_what_the_declared_run_does(monkeypatch):
    """A tower of 5 boxes at rest: of its 340 found contacts only the candidates get record columns,
    and the run reports the declared tower's forces, modes and phases on the 10 that touch and an
    open contact without force on every other one."""
    made = windows_of_runs(monkeypatch)
    found, q0 = box_tower(5, True)
    declared, _ = box_tower(5, False)
    run = nr.simulate(found, q0, np.zeros_like(q0), 0.3, h=1e-3)
    reference = nr.simulate(declared, q0, np.zeros_like(q0), 0.3, h=1e-3)
    window = made[0]
    contacts, _, _ = window.columns()
    assert 10 <= contacts.size <= 40 and window.out.p_normal.shape[1] <= 40  # not 340
    np.testing.assert_allclose(run.q, reference.q, rtol=0, atol=1e-12)
    names = [c.name for c in found.contacts]
    touching = [names.index(c.name) for c in declared.contacts]
    assert set(touching) <= set(contacts.tolist())
    scale = 5 * 9.81
    np.testing.assert_allclose(run.normal_force[:, touching], reference.normal_force, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(run.tangential_force[:, touching], reference.tangential_force, atol=1e-9 * scale)
    assert run.modes[:, touching].tolist() == reference.modes.tolist()
    others = np.setdiff1d(np.arange(len(names)), touching)
    assert not run.normal_force[:, others].any() and not run.tangential_force[:, others].any()
    assert set(run.modes[:, others].ravel()) == {"open"}
    assert all([(p.mode, p.t_start, p.t_end) for p in run.phases[names[i]]] == [("open", 0.0, 0.3)] for i in others)
    for name in declared.contacts:
        assert [(p.mode, p.t_start, p.t_end) for p in run.phases[name.name]] == \
            [(p.mode, p.t_start, p.t_end) for p in reference.phases[name.name]]
    end = run.end_state
    assert not end.p_normal[:, others].any() and not end.states[:, others].any()
    assert np.all(np.signbit(end.slip[:, np.setdiff1d(others, contacts)]))  # −0.0, as a contact out of reach's


def pushed_tower():
    """The found tower with its top box thrown sideways and the bottom one pushed: boxes slide,
    tip and land on one another (new candidates all along, impacts, phases)."""
    scene, q0 = box_tower(4, True)
    v0 = np.zeros_like(q0)
    v0[0], v0[9], v0[11] = 0.4, -1.5, 3.0
    return scene, q0, v0


@pytest.mark.parametrize("options", [{}, {"save_every": 0.01}, {"solver": "pgs"}])
def test_records_widened_from_one_column_give_the_very_same_run(options, monkeypatch):
    """Records that start with one column, widened each time a new candidate finds them full (the
    step run again from its start), give the run of records wide enough from the start."""
    from nonsmooth_rod.integrators import moreau_jean

    scene, q0, v0 = pushed_tower()
    made = windows_of_runs(monkeypatch)
    wide = nr.simulate(scene, q0, v0, 0.4, h=1e-3, **options)
    monkeypatch.setattr(moreau_jean, "RECORD_COLUMNS_PER_BODY", 0)
    monkeypatch.setattr(moreau_jean, "MIN_RECORD_COLUMNS", 1)
    narrow = nr.simulate(scene, q0, v0, 0.4, h=1e-3, **options)
    assert made[0].out.p_normal.shape[1] >= made[1].columns()[0].size > 1  # widened, and as many given
    assert made[1].out.p_normal.shape[1] < len(scene.contacts)
    assert_same_run(narrow, wide)
    assert len(wide.impacts) >= 1 and sum(len(p) > 1 for p in wide.phases.values()) >= 3


def test_a_stopped_and_a_resumed_run_with_few_columns_go_on_as_the_whole_run(monkeypatch):
    """A stop condition's replay and a restart from an end state keep each contact's records in
    its column (the restart gives columns to the contacts whose history has records)."""
    from nonsmooth_rod.integrators import moreau_jean

    scene, q0, v0 = pushed_tower()
    whole = nr.simulate(scene, q0, v0, 0.4, h=1e-3)
    monkeypatch.setattr(moreau_jean, "RECORD_COLUMNS_PER_BODY", 0)
    monkeypatch.setattr(moreau_jean, "MIN_RECORD_COLUMNS", 2)
    stopped = nr.simulate(scene, q0, v0, 0.4, h=1e-3, stop=lambda t, q, v: t >= 0.2)
    assert stopped.status == "stopped"
    again = nr.simulate(scene, stopped.q[-1], stopped.v[-1], 0.4, h=1e-3, t0=stopped.t[-1],
                        resume=stopped.end_state)
    assert_same_continuation(whole, again, float(stopped.t[-1]))
    assert again.end_state.as_dict() == whole.end_state.as_dict()


def test_records_lent_to_the_next_run_keep_no_column_of_the_last(monkeypatch):
    """A short run's window records, lent to the scene's next run (integrators/scene_plans.py),
    come back without the last run's columns or values: a run from another state, whose
    candidates are other contacts, is the fresh run bit for bit."""
    from nonsmooth_rod.integrators import moreau_jean
    from nonsmooth_rod.integrators.scene_plans import forget_plans

    scene, q0, v0 = pushed_tower()
    made = windows_of_runs(monkeypatch)
    monkeypatch.setattr(moreau_jean, "RECORD_COLUMNS_PER_BODY", 20)  # never widened: the lent set is the run's
    forget_plans()
    nr.simulate(scene, q0, v0, 0.05, h=1e-3)  # lends its records (a short window)
    first = made[0].columns()[0].copy()
    q1, v1 = q0.copy(), -v0
    q1[0::3] += 0.05 * np.arange(4)  # a leaning stack: other corners near
    lent = nr.simulate(scene, q1, v1, 0.05, h=1e-3)
    assert made[1].first_out is made[0].out and made[1].out is made[0].out  # the same records, lent
    forget_plans()
    fresh = nr.simulate(scene, q1, v1, 0.05, h=1e-3)
    assert made[2].out is not made[0].out
    assert made[1].columns()[0].tolist() == made[2].columns()[0].tolist() != first.tolist()  # other candidates
    assert_same_run(lent, fresh)


def test_the_records_of_a_long_found_run_take_memory_by_the_contacts_that_come_near(monkeypatch):
    """20 000 steps of the found tower at rest (one window): its records take the columns of the
    few dozen candidates, not the 340 listed contacts' (218 MB); tracemalloc's peak of the run."""
    import tracemalloc

    made = windows_of_runs(monkeypatch)
    scene, q0 = box_tower(5, True)
    nr.simulate(scene, q0, np.zeros_like(q0), 0.01, h=1e-3)  # warm: packed, compiled
    steps = 20_000
    tracemalloc.start()
    try:
        nr.simulate(scene, q0, np.zeros_like(q0), steps * 1e-3, h=1e-3, save_every=0.1)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    window = made[-1]
    given = window.columns()[0].size
    assert given <= 40 and window.out.p_normal.shape[1] <= 2 * max(given, 20)
    rows = steps + 4
    records = rows * 8 * (2 * scene.n_dof + 4 * window.out.p_normal.shape[1])  # q, v and 4 records a column
    kept = 201 * len(scene.contacts) * (8 + 8 + 1 + 8)  # the result's samples: N, T, codes, modes
    assert peak <= records + kept + (3 << 20), (peak, records)  # (+ the windows' temporaries)
    assert peak < rows * 8 * 4 * len(scene.contacts) / 4  # (every listed contact's records: 218 MB)


def test_samples_hold_each_steps_state_and_its_records_over_its_own_size_compiled_or_not():
    """A kept sample at step k is the state there and the step that led to it divided by that
    step's size: a = Δv/h (h_last for the shortened last step), t = k h (t_end at the last); the
    first sample, which no step leads to, has a = NaN and no forces. The compiled kernel that takes
    them (moreau_jean_records.samples_into) and its interpreted twin give the same bits."""
    toy = toys.BlockOnIncline()
    scene, (q0, v0) = toy.scene(), toy.initial_state()
    h, t_end = 1e-3, 0.0415  # 41 whole steps, then one of 0.5 ms
    compiled = nr.simulate(scene, q0, v0, t_end, h=h, solver="lemke")
    plain = nr.simulate(scene, q0, v0, t_end, h=h, solver="lemke", fast=False)
    assert compiled.stats["compiled"] or not nr._jit.ENABLED
    t, v, a = compiled.t, compiled.v, compiled.trajectory.a
    k = np.arange(t.size)
    assert t.size == 43 and t[-1] == t_end
    np.testing.assert_array_equal(t[:-1], k[:-1] * h)
    h_last = t_end - 41 * h
    steps = np.r_[np.full(41, h), h_last]
    np.testing.assert_array_equal(a[1:], (v[1:] - v[:-1]) / steps[:, None])
    assert np.isnan(a[0]).all() and not compiled.normal_force[0].any() and not compiled.tangential_force[0].any()
    # flat on the incline, its corners' normal forces carry the weight's normal part, m g cos α
    np.testing.assert_allclose(compiled.normal_force[1:].sum(axis=1), toy.mass * toy.g * math.cos(toy.angle),
                               rtol=1e-9)
    for name in ("t", "q", "v", "normal_force", "tangential_force"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(compiled, name), err_msg=name)
    np.testing.assert_array_equal(plain.trajectory.a, a)
    assert plain.modes.tolist() == compiled.modes.tolist()
