"""A scene packed once for the runs that repeat it (integrators/scene_plans.py): a repeated run
is the fresh run bit for bit, and any change of the scene between runs is seen."""
import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.integrators import scene_plans
from nonsmooth_rod.integrators.scene_plans import forget_plans, scene_plan
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnLine, Line, LinearRelation
from nonsmooth_rod.model.forces import Spring
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.motion import DrivenBody, Harmonic
from nonsmooth_rod.model.scene import Scene

H, T_END = 1e-3, 0.3


def ball_scene(mu=0.3, restitution=0.0, radius=0.1):
    """A spinning ball thrown onto a floor: it lands, slides, then rolls (an impact, slip and
    stick phases, located events)."""
    floor = DiskOnLine(0, (0.0, 0.0), Line(), radius, ContactLaw.of(mu, restitution=restitution), "floor")
    return Scene([RigidBody(1.0, 0.004)], [floor])


Q0, V0 = np.array([0.0, 0.15, 0.0]), np.array([1.0, -1.0, 20.0])


def run(scene, **options):
    return nr.simulate(scene, Q0, V0, T_END, h=H, **options)


def same_bits(a, b) -> bool:
    """The same numbers bit for bit (-0.0 is not 0.0, NaN is NaN); words equal."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype == object:
        return a.shape == b.shape and b.dtype == object and np.array_equal(a, b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def assert_identical(got, want):
    """The same run bit for bit: samples, modes, phases, events, impacts, end state, counts."""
    for name in ("t", "q", "v", "normal_force", "tangential_force", "modes"):
        assert same_bits(getattr(got, name), getattr(want, name)), name
    assert got.trajectory.a.tobytes() == want.trajectory.a.tobytes()
    assert got.phases == want.phases and got.events == want.events
    assert [(i.t, i.contact) for i in got.impacts] == [(i.t, i.contact) for i in want.impacts]
    for a, b in zip(got.impacts, want.impacts):
        assert all(same_bits(x, y) for x, y in zip((a.q, a.v_before, a.v_after), (b.q, b.v_before, b.v_after)))
    for name in ("q", "v", "p_normal", "p_tangent", "slip", "states", "was_closed", "grazing", "slip_sign"):
        assert same_bits(getattr(got.end_state, name), getattr(want.end_state, name)), name
    assert (got.status, got.message, got.steps) == (want.status, want.message, want.steps)
    assert got.stats == want.stats


@pytest.fixture(autouse=True)
def no_kept_plans():
    forget_plans()
    yield
    forget_plans()


def test_a_repeated_run_reuses_the_plan_and_is_the_fresh_run_bit_for_bit():
    scene = ball_scene()
    first = run(scene)
    assert {p.mode for p in first.phases["floor"]} >= {"open", "slip+", "stick"}  # a run with every kind of row
    plan = scene_plan(scene)
    second = run(scene)
    assert scene_plan(scene) is plan  # kept, not packed again
    assert_identical(second, first)
    assert_identical(run(ball_scene()), first)  # an equal scene, packed afresh


def test_a_kept_result_is_not_changed_by_the_next_runs():
    """The per-run arrays a plan lends come back to it: nothing a result keeps points into them."""
    scene = ball_scene()
    first = run(scene)
    kept = {name: getattr(first.end_state, name).copy() for name in ("q", "v", "was_closed", "slip_sign")}
    q = first.q.copy()
    nr.simulate(scene, Q0, -V0, T_END, h=H)  # another run of the same scene, other numbers
    assert same_bits(first.q, q)
    assert all(same_bits(getattr(first.end_state, k), v) for k, v in kept.items())


def test_an_end_state_first_read_after_later_runs_is_its_own_runs():
    """A short run's end state is built on first read from the arrays its plan lends to the next
    run, which has it copied out first while the result is alive: read only after three more runs
    of the scene (other numbers), it is the end state of the same run of a scene packed afresh."""
    scene = ball_scene()
    first = run(scene)
    # the same window length, every result kept: the plan's sets are all still read, so the third
    # run reuses first's arrays
    later = [nr.simulate(scene, Q0, v0, T_END, h=H) for v0 in (-V0, 2 * V0, 0.5 * V0)]
    want = run(ball_scene()).end_state
    for name in ("q", "v", "p_normal", "p_tangent", "slip", "states", "was_closed", "grazing", "slip_sign"):
        assert same_bits(getattr(first.end_state, name), getattr(want, name)), name
    assert (first.end_state.step, first.end_state.origin) == (want.step, want.origin)
    assert same_bits(later[0].end_state.v, nr.simulate(ball_scene(), Q0, -V0, T_END, h=H).end_state.v)


@pytest.mark.parametrize("end_state_first", [False, True])
def test_phases_first_read_after_later_runs_are_its_own_runs(end_state_first):
    """A short run's last rows (the state runs and boundary rows its phases are located from) are
    taken on first need from the records its plan lends to the next runs (Collector.settle_rows):
    its phases and events, read only after three more runs of the scene with other numbers
    (before or after its end state), are those of the same run of a scene packed afresh."""
    scene = ball_scene()
    first = run(scene)
    if end_state_first:
        first.end_state
    later = [nr.simulate(scene, Q0, v0, T_END, h=H) for v0 in (-V0, 2 * V0, 0.5 * V0)]
    want = run(ball_scene())
    assert {p.mode for p in want.phases["floor"]} >= {"open", "slip+", "stick"}
    assert first.phases == want.phases and first.events == want.events
    other = nr.simulate(ball_scene(), Q0, -V0, T_END, h=H)
    assert later[0].phases == other.phases and later[0].events == other.events


@pytest.mark.parametrize("change", ["law", "radius", "line", "contacts list", "weight in place", "forces"])
def test_a_change_of_the_scene_between_runs_is_seen(change):
    """Each change gives the run of a scene built with it from the start, not the kept plan's."""
    scene = ball_scene()
    run(scene)
    if change == "law":
        scene.contacts[0].law = ContactLaw.of(0.05)
        want = run(ball_scene(mu=0.05))
    elif change == "radius":
        scene.contacts[0].radius = 0.12
        want = run(ball_scene(radius=0.12))
    elif change == "line":
        scene.contacts[0].line = Line((0.0, -0.01))
        fresh = ball_scene()
        fresh.contacts[0].line = Line((0.0, -0.01))
        want = run(fresh)
    elif change == "contacts list":
        scene.contacts[0] = ball_scene(restitution=0.5).contacts[0]
        want = run(ball_scene(restitution=0.5))
    elif change == "weight in place":
        scene.weight[1] *= 0.5
        fresh = ball_scene()
        fresh.weight[1] *= 0.5
        want = run(fresh)
    else:
        scene.forces.append(Spring(0, body_b=None, point_b=(0.0, 0.3), stiffness=50.0))
        want = run(Scene(scene.bodies, [ball_scene().contacts[0]], forces=list(scene.forces)))
    got = run(scene)
    assert not same_bits(got.q, run(ball_scene()).q)  # the change matters to the run
    assert_identical(got, want)


def test_a_scene_with_rows_changeable_in_place_is_packed_for_every_run():
    """A LinearRelation's rows are dicts (changeable without an assignment the relation sees):
    such a scene keeps no plan, and a change in place is seen."""
    floor = LinearRelation({0: (0.0, 1.0, 0.0)}, gap0=-0.1, tangent={0: (1.0, 0.0, 0.0)},
                           law=ContactLaw.of(0.3), name="floor")
    scene = Scene([RigidBody(1.0, 0.004)], [floor])
    before = run(scene)
    assert scene_plan(scene) is not scene_plan(scene)
    floor.normal[0] = (0.0, 1.0, 0.5)  # in place: no assignment
    after = run(scene)
    fresh = Scene([RigidBody(1.0, 0.004)], [LinearRelation({0: (0.0, 1.0, 0.5)}, gap0=-0.1,
                                                           tangent={0: (1.0, 0.0, 0.0)},
                                                           law=ContactLaw.of(0.3), name="floor")])
    assert not same_bits(after.q, before.q)
    assert_identical(after, run(fresh))


def test_a_scene_with_a_driven_body_is_packed_for_every_run():
    """The loop writes a driven scene's rows while it runs: never kept."""
    scene = Scene([RigidBody(1.0, 0.004), RigidBody(1.0, 0.004)], [ball_scene().contacts[0]],
                  driven=[DrivenBody(1, Harmonic(amplitude=(0.1, 0.0, 0.0), frequency_hz=2.0))])
    q0, v0 = np.r_[Q0, 2.0, 1.0, 0.0], np.r_[V0, 0.0, 0.0, 0.0]
    first = nr.simulate(scene, q0, v0, T_END, h=H)
    assert scene_plan(scene) is not scene_plan(scene)
    assert_identical(nr.simulate(scene, q0, v0, T_END, h=H), first)


def test_kept_plans_are_bounded():
    scenes = [ball_scene() for _ in range(scene_plans.MAX_PLANS + 3)]
    for scene in scenes:
        scene_plan(scene)
    assert len(scene_plans._PLANS) == scene_plans.MAX_PLANS
    assert scene_plan(scenes[-1]) is scene_plan(scenes[-1])


def test_the_arrays_a_plan_lends_are_bounded():
    """A few sets (runs of many lengths do not pile up windows), each small (a long run's window is
    not kept)."""
    from nonsmooth_rod.integrators.moreau_jean import _lend, _new_work
    from nonsmooth_rod.integrators.moreau_jean_records import HISTORY, Window

    scene = ball_scene()
    kept = [nr.simulate(scene, Q0, V0, steps * H, h=H) for steps in range(5, 5 + 3 * scene_plans.MAX_SPARES)]
    kept += [nr.simulate(scene, Q0, V0, 5 * H, h=H) for _ in range(3)]  # results kept: a second set, not more
    plan = scene_plan(scene)
    assert len(plan._spares) == scene_plans.MAX_SPARES
    long_window = Window(scene.n_dof, 1, 50_000)
    assert not _lend(plan, None, _new_work(1, scene.n_dof, plan.joints), long_window)
    assert long_window.rows not in plan._spares
    assert all(kept[0][1] is not long_window.out for kept in plan._owners.values())  # nor kept alive
    del kept  # their results gone: every set free
    taken = [plan.borrow(HISTORY + 5) for _ in range(scene_plans.SETS_PER_KEY)]
    assert all(t is not None for t in taken) and plan.borrow(HISTORY + 5) is None  # each set to one run at a time
    assert len({id(t) for t in taken}) == scene_plans.SETS_PER_KEY
