"""The broad phase: listing every disk pair changes nothing but the listing."""
import numpy as np
import pytest

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnDisk, DiskOnLine, Line
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.packing import pack_scene
from nonsmooth_rod.model.scene import Scene

R = 0.05


def _row(n, all_pairs):
    """n balls 1 mm apart on a floor, the first rolling into the others (a Newton's cradle with gaps)."""
    law = ContactLaw.of(0.3, 0.2, 0.9)
    bodies = [RigidBody(0.1, 0.4 * 0.1 * R * R, f"b{i}") for i in range(n)]
    contacts = [DiskOnLine(i, (0.0, 0.0), Line(), R, law, f"floor{i}") for i in range(n)]
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)] if all_pairs else [(i, i + 1) for i in range(n - 1)]
    contacts += [DiskOnDisk(j, i, R, R, law=law, name=f"{i}-{j}") for i, j in pairs]
    q0 = np.zeros(3 * n)
    q0[0::3], q0[1::3] = np.arange(n) * (2 * R + 1e-3), R
    v0 = np.zeros(3 * n)
    v0[0], v0[2] = 1.0, -1.0 / R
    return Scene(bodies, contacts), q0, v0



def _activated(packed, q, v, h, gamma) -> list:
    """The contacts the step would activate at (q, v): gap + γ h u_N within the activation's round-off."""
    from nonsmooth_rod.integrators.moreau_jean_loop import ACTIVATION_ROUNDOFF
    from nonsmooth_rod.model.packing import contact_kinematics, row_dot

    hn, ht = np.zeros((packed.n_contacts, 6)), np.zeros((packed.n_contacts, 6))
    found = []
    for i in range(packed.n_contacts):
        gap, _ = contact_kinematics(packed.contacts, packed.contact_index, i, q, v, hn[i], ht[i])
        if gap + gamma * h * row_dot(hn, packed.contact_index, i, v) <= ACTIVATION_ROUNDOFF:
            found.append(i)
    return found

def test_all_pairs_listed_give_the_neighbours_run():
    # 15 listed pairs go through the broad phase (more than BROAD_PHASE_MIN_PAIRS), the 5 neighbour
    # pairs do not: the sorted and the unsorted run must agree
    from nonsmooth_rod.integrators.moreau_jean_loop import BROAD_PHASE_MIN_PAIRS

    assert 5 <= BROAD_PHASE_MIN_PAIRS < 15
    runs = [MoreauJean(MoreauJeanOptions(h=1e-3)).run(*_row(6, all_pairs), 0.1) for all_pairs in (False, True)]
    neighbours, everything = runs
    pair_impacts = [i.contact for i in neighbours.impacts if not i.contact.startswith("floor")]
    assert pair_impacts[:5] == ["0-1", "1-2", "2-3", "3-4", "4-5"]  # the impulse runs down the row
    assert [i.contact for i in everything.impacts] == [i.contact for i in neighbours.impacts]
    q = neighbours.trajectory.q  # the far pairs stay open: the same run to round-off of its positions
    assert np.max(np.abs(everything.trajectory.q - q)) <= 500 * np.finfo(float).eps * np.max(np.abs(q))
    far = [name for name in everything.contact_names if name not in neighbours.contact_names]
    assert len(far) == 10 and all(not everything.phases[n] or {p.mode for p in everything.phases[n]} == {"open"}
                                  for n in far)


def test_disk_pairs_are_packed_once_per_disk_and_sorted():
    packed = pack_scene(_row(4, True)[0])
    assert packed.disks.shape == (4, 3) and list(packed.disk_body) == [1, 0, 2, 3]  # first seen: body_a of 0-1
    assert np.all(np.diff(packed.pair_keys) > 0) and len(packed.pair_keys) == 6


def _boxes_on_a_floor(n, seed):
    """n boxes of found contacts (every pair, and each on the floor) placed near each other at
    random — within a box's size, some overlapping — with random velocities up to 30 m/s and
    30 rad/s, and their packed scene."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.collision import find_contacts

    rng = np.random.default_rng(seed)
    bodies = [RigidBody(1.0, 0.02, f"box{k}") for k in range(n)]
    shapes = {b.name: nr.Polygon.rectangle(0.4, 0.3) for b in bodies}
    contacts = find_contacts(bodies, shapes, {"floor": Line()})
    q = np.column_stack([rng.uniform(-0.4, 0.4, n), rng.uniform(-0.1, 0.6, n), rng.uniform(-np.pi, np.pi, n)])
    v = rng.uniform(-30.0, 30.0, (n, 3))
    return pack_scene(Scene(bodies, contacts)), q.ravel(), v.ravel()


def _candidates(packed, q, v, h, sweep):
    from nonsmooth_rod.integrators import moreau_jean_loop as loop

    n, nc = packed.disks.shape[0], packed.n_contacts
    x, y, reach = np.empty(n), np.empty(n), np.empty(n)
    loop._disk_reach(h, q, v, packed.disks, packed.disk_body, x, y, reach, np.empty(q.size))
    candidate, was_closed = np.ones(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64)
    if sweep:
        order = np.argsort(y)
        loop._sweep_and_prune(y, x, reach, order, packed.disk_body, packed.pair_keys, packed.pair_contact,
                              was_closed, candidate)
    else:
        loop._listed_pairs_in_reach(x, y, reach, packed.pair_keys, packed.pair_contact, was_closed, candidate)
    loop.lines_in_reach(0.5 * h, q, v, packed.contacts, packed.contact_index, was_closed, candidate)
    return candidate


def test_the_broad_phase_leaves_out_no_contact_the_step_activates():
    """Exactness of the pre-tests before the kinematics: whichever way the circles' pairs are
    tested (each listed pair, or sweep and prune), and for a point on the line, every contact
    whose activation test (predicted gap γ h ahead ≤ the round-off margin) holds this step is
    kept — fast bodies close to each other included — and both ways keep the same contacts."""
    h, gamma, activated, left_out = 1e-2, 0.5, 0, 0
    for seed in range(12):
        packed, q, v = _boxes_on_a_floor(4, seed)
        listed, swept = _candidates(packed, q, v, h, False), _candidates(packed, q, v, h, True)
        assert np.array_equal(listed, swept)
        for i in _activated(packed, q, v, h, gamma):
            activated += 1
            assert listed[i] == 1, (seed, i)
        left_out += int(np.sum(listed == 0))
    assert activated > 50 and left_out > 100  # the check has cases on both sides


def test_fast_boxes_do_not_pass_through_the_floor_or_each_other():
    """A box thrown at 40 m/s (4 cm a step) into a box at rest, and one dropped at 40 m/s onto the
    floor, found contacts: the pre-tests leave out the far pairs, never the ones the step needs —
    the thrown box strikes the resting one and stays behind it (equal masses, e = 0: they go on
    together at 20 m/s, less what the floor's friction takes), the dropped one lands on its face.
    The scheme's own bound on a penetration is one step's travel: a contact enters the step when
    its gap is within γ h |u_N| (it may be up to (1 − γ) h |u_N| deep then), and the θ-method's
    positions go on (1 − θ) h |u_N| before the impact stops them (γ = θ = 1/2): 4 cm at 40 m/s
    (a pass-through: 30 or 40 cm)."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.collision import deepest_overlap, find_contacts

    bodies = [RigidBody(1.0, 0.02, name) for name in ("still", "thrown", "dropped")]
    shapes = {b.name: nr.Polygon.rectangle(0.4, 0.3) for b in bodies}
    law = ContactLaw.of(0.1, 0.1)
    contacts = find_contacts(bodies, shapes, {"floor": Line()}, nr.PairLaws(default=law))
    q0 = np.array([0.0, 0.15, 0.0, -1.0, 0.15, 0.0, 3.0, 1.15, 0.0])
    v0 = np.array([0.0, 0.0, 0.0, 40.0, 0.0, 0.0, 0.0, -40.0, 0.0])
    h, speed = 1e-3, 40.0
    result = nr.simulate(Scene(bodies, contacts), q0, v0, 0.04, "moreau-jean", h=h)
    assert result.status == "ok", result.message
    q, v = result.trajectory.q, result.trajectory.v
    deepest = h * (speed + 9.81 * 0.04)  # the step's travel at the fastest (gravity adds 0.4 m/s)
    assert np.max(q[:, 3] + 0.4 - q[:, 0]) <= deepest  # the thrown box stays behind the struck one's face
    assert v[-1, 0] == pytest.approx(20.0, abs=0.1) and v[-1, 3] == pytest.approx(v[-1, 0], abs=1e-6)
    assert abs(q[-1, 7] - 0.15) <= deepest and v[-1, 7] == pytest.approx(0.0, abs=1e-9)
    assert deepest_overlap(bodies, shapes, q, [Line()]) <= deepest
    struck = {frozenset(side.split(".")[0] for side in i.contact.split("/")) for i in result.impacts}
    assert {frozenset({"still", "thrown"}), frozenset({"dropped", "floor"})} <= struck


def _kept_marks(packed, q_build, q, v, h, gamma):
    """broad_candidates' marks at (q, v) on a kept list built at q_build (as a run's step after
    its build), and whether (q, v) asked for a rebuild; with the scratch a run gives it."""
    from nonsmooth_rod.integrators import moreau_jean_loop as loop

    nc, n_dof = packed.n_contacts, q.size
    n_kept, n_pose = loop.kept_sizes(n_dof, packed.disks.shape[0], nc, packed.pair_keys.shape[0])
    kept, kept_pose = np.zeros(n_kept, dtype=np.int64), np.zeros(n_pose)
    candidate, was_closed, room = np.ones(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64), np.empty(11 * nc)
    args = (packed.disks, packed.disk_body, packed.pair_keys, packed.pair_contact, packed.contacts,
            packed.contact_index, was_closed, candidate, room, kept, kept_pose, np.zeros(nc + 1, dtype=np.int64))
    loop.broad_candidates(h, gamma, q_build, np.zeros(n_dof), *args)  # the build
    loop.broad_candidates(h, gamma, q, v, *args)
    return candidate, kept[0] + kept[1], not np.array_equal(kept_pose[:n_dof], q_build)  # (the pose of the build)


def _within_skin(packed, q_build, rng, h, gamma, share):
    """A state (q, v) whose displacement bound from q_build (broad_candidates' docstring) uses
    `share` of BROAD_PHASE_REBUILD × the skin per body, spread over translation, turn and speed."""
    from nonsmooth_rod.integrators import moreau_jean_loop as loop

    n_dof = q_build.size
    pose = np.zeros(n_dof + n_dof // 3 + 2)
    skin = loop._skin_and_levers(packed.disks, packed.disk_body, packed.contacts, packed.contact_index, pose, n_dof)
    levers, budget = pose[n_dof: n_dof + n_dof // 3], share * loop.BROAD_PHASE_REBUILD * skin
    parts = rng.dirichlet(np.ones(3), size=n_dof // 3) * budget  # translation, turn, one step's travel
    direction = rng.normal(size=(n_dof // 3, 3))
    dq, v = np.zeros((n_dof // 3, 3)), np.zeros((n_dof // 3, 3))
    signs = np.sign(direction[:, :2])
    dq[:, :2] = signs * (parts[:, :1] / 2)
    dq[:, 2] = np.sign(direction[:, 2]) * parts[:, 1] / levers
    step = h * max(1.0, abs(gamma))
    v[:, :2] = -signs * (parts[:, 2:] / 4) / step  # half the travel in translation, half in the turn
    v[:, 2] = np.sign(direction[:, 2]) * (parts[:, 2] / 2) / (levers * step)
    return q_build + dq.ravel(), v.ravel()


def _boxes_near_touching(n, seed):
    """A leaning tower of n boxes (found contacts, each pair and the floor), each a random gap
    (−3 mm … 1 cm, within the 3 cm skin) above the one below, shifted up to 15 cm and turned up to
    0.05 rad: features on both sides of every reach."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.collision import find_contacts

    rng = np.random.default_rng(seed)
    bodies = [RigidBody(1.0, 0.02, f"box{k}") for k in range(n)]
    shapes = {b.name: nr.Polygon.rectangle(0.4, 0.3) for b in bodies}
    contacts = find_contacts(bodies, shapes, {"floor": Line()})
    tilt = rng.uniform(-0.05, 0.05, n)
    lift = 0.15 * np.cos(tilt) + 0.2 * np.abs(np.sin(tilt))  # the lowest corner's height over the centre
    y = np.cumsum(2 * lift + rng.uniform(-3e-3, 1e-2, n)) - lift
    q = np.column_stack([rng.uniform(-0.15, 0.15, n), y, tilt])
    return pack_scene(Scene(bodies, contacts)), q.ravel()


def _kernel_rejects(packed, i, q, v) -> bool:
    """Whether the kinematics kernel gives contact i at (q, v) an infinite gap and zero rows (its
    pair of features is not the touching one)."""
    from nonsmooth_rod.model.packing import contact_kinematics

    hn, ht = np.full(6, np.nan), np.full(6, np.nan)
    gap, _ = contact_kinematics(packed.contacts, packed.contact_index, i, q, v, hn, ht)
    return gap == np.inf and not np.any(hn) and not np.any(ht)


def test_the_kept_list_marks_what_the_whole_broad_phase_marks():
    """Verlet lists: the kept list built at one pose, tested at another whose circles moved by up to
    the rebuild bound (translation, turn and one step's travel at 25–60 m/s — the skin is 3 cm:
    these are h = 1e-4 steps), marks exactly the contacts the whole broad phase (each listed pair,
    and lines_in_reach) marks there, less vertex–edge pairs the kernel's cone rule rejects there
    (left out at the build for every pose until the next) — and so keeps every contact the step
    activates — while holding far fewer than are listed; past the bound, the list is rebuilt."""
    rng = np.random.default_rng(7)
    h, gamma, activated, in_reach, kept_total, listed_total, out_of_cone = 1e-4, 0.5, 0, 0, 0, 0, 0
    for seed in range(20):
        packed, q_build = _boxes_near_touching(4, seed)
        q, v = _within_skin(packed, q_build, rng, h, gamma, 0.999)
        marks, n_kept, rebuilt = _kept_marks(packed, q_build, q, v, h, gamma)
        assert not rebuilt
        whole = _candidates(packed, q, v, h, False)  # lines_in_reach at 0.5 h: γ h
        assert np.all(marks <= whole), seed
        for i in np.flatnonzero(whole > marks):
            out_of_cone += 1
            assert _kernel_rejects(packed, i, q, v), (seed, i)
        for i in _activated(packed, q, v, h, gamma):
            activated += 1
            assert marks[i] == 1, (seed, i)
        in_reach += int(np.sum(whole))
        kept_total += n_kept
        listed_total += packed.pair_keys.shape[0] + 4 * 4
        q_far, v_far = _within_skin(packed, q_build, rng, h, gamma, 1.2)
        assert _kept_marks(packed, q_build, q_far, v_far, h, gamma)[2]  # past the bound: rebuilt
    assert activated > 10 and kept_total < 0.5 * listed_total  # cases on both sides, and a list that keeps few
    assert out_of_cone > 20  # the cone rule left pairs out (a box's corner beside its neighbour's side)
    assert in_reach < packed.n_contacts * 12  # some contacts left out (the comparison is not all ones)


def test_a_run_on_kept_lists_is_the_run_rebuilding_them_every_step():
    """Boxes thrown onto a floor and onto each other (found contacts), h = 1 ms: the compiled loop's
    whole run keeps its broad-phase list between rebuilds; the same run with a (zero) Python force
    goes one step a call, each call building the list afresh. Same trajectory and impulses, bit
    for bit (the kept list marks the very same candidates)."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.collision import find_contacts

    bodies = [RigidBody(1.0, 0.02, f"box{k}") for k in range(3)]
    shapes = {b.name: nr.Polygon.rectangle(0.4, 0.3) for b in bodies}
    contacts = find_contacts(bodies, shapes, {"floor": Line()}, nr.PairLaws(default=ContactLaw.of(0.5, 0.4, 0.2)))
    q0 = np.array([0.0, 0.15, 0.0, -0.7, 0.5, 0.3, 0.1, 0.9, -0.2])
    v0 = np.array([0.0, 0.0, 0.0, 4.0, 1.0, -2.0, 0.5, -3.0, 5.0])
    runs = [nr.simulate(Scene(bodies, contacts, applied_force=force), q0, v0, 0.4, "moreau-jean", h=1e-3)
            for force in (None, lambda t, q, v: np.zeros(9))]
    assert all(r.status == "ok" for r in runs), [r.message for r in runs]
    kept, rebuilt = runs
    assert np.array_equal(kept.trajectory.q, rebuilt.trajectory.q)
    assert np.array_equal(kept.trajectory.v, rebuilt.trajectory.v)
    assert [(i.contact, i.t) for i in kept.impacts] == [(i.contact, i.t) for i in rebuilt.impacts]
    assert len({i.contact for i in kept.impacts}) >= 4  # boxes struck the floor and each other


def test_a_spinning_corner_strikes_a_side_the_cone_rule_left_out():
    """A box spinning at 40 rad/s (its corners at 10 m/s, 2.3° a step) thrown at 3 m/s into the
    side of a box at rest: at each build of the kept list its corners pointing away from the
    struck side are left out by the cone rule (_out_of_cone_until_rebuilt), and they come round
    onto that side within the run. The run on kept lists is the run whose every step runs the
    whole broad phase (a zero Python force: one step a call, no list kept), bit for bit, every
    record of every contact included; a corner that faced away at the start strikes the side, and
    the boxes never overlap by more than one step's travel of the fastest corner."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.model.collision import deepest_overlap, find_contacts

    bodies = [RigidBody(1.0, 0.02, name) for name in ("still", "spinning")]
    shapes = {b.name: nr.Polygon.rectangle(0.4, 0.3) for b in bodies}
    contacts = find_contacts(bodies, shapes, {"floor": Line()}, nr.PairLaws(default=ContactLaw.of(0.3, 0.3, 0.5)))
    q0 = np.array([0.0, 0.15, 0.0, -0.6, 0.35, 0.0])
    v0 = np.array([0.0, 0.0, 0.0, 3.0, 0.0, 40.0])
    h = 1e-3
    runs = [nr.simulate(Scene(bodies, contacts, applied_force=force), q0, v0, 0.25, "moreau-jean", h=h)
            for force in (None, lambda t, q, v: np.zeros(6))]
    assert all(r.status == "ok" for r in runs), [r.message for r in runs]
    kept, whole = runs
    assert np.array_equal(kept.trajectory.q, whole.trajectory.q)
    assert np.array_equal(kept.trajectory.v, whole.trajectory.v)
    for name in ("normal_force", "tangential_force", "modes"):
        assert np.array_equal(getattr(kept.trajectory, name), getattr(whole.trajectory, name)), name
    assert kept.phases == whole.phases
    for name in ("p_normal", "p_tangent", "slip", "states"):  # the end state's records, bits of ±0 included
        a, b = getattr(kept.end_state, name), getattr(whole.end_state, name)
        assert a.dtype == b.dtype and np.array_equal(a.view(np.int64), b.view(np.int64)), name
    assert [(i.contact, i.t) for i in kept.impacts] == [(i.contact, i.t) for i in whole.impacts]
    from nonsmooth_rod.model.contact_kernels import vertex_cone_margin

    struck = [i.contact for i in kept.impacts if i.contact.endswith("/still.e3")]  # the struck box's left side
    assert struck, [i.contact for i in kept.impacts]
    i = [c.name for c in contacts].index(struck[0])  # a corner that faced away at the start: left out then
    assert vertex_cone_margin(pack_scene(Scene(bodies, contacts)).contacts[i], 1, 0, q0) < -0.5
    corner_speed = 3.0 + 40.0 * np.hypot(0.2, 0.15)
    assert deepest_overlap(bodies, shapes, kept.trajectory.q, [Line()]) <= h * corner_speed
