"""The one Moreau–Jean loop, on arrays: compiled with numba, or plain Python from the same source.

A step of size h from (q_k, v_k), for a packed scene (model.packing):

    begin_step   v_free = v_k + h M⁻¹ f; contact kinematics; the contacts that enter the step
    assemble     W = H M⁻¹ Hᵀ over the active contacts, q_step, the slip guesses, μs, μd
    (solve)      the exact two-coefficient law (solvers.two_coefficient.two_coefficient_kernel,
                 or the Python solve_two_coefficient for the QP solvers)
    finish_step  v_{k+1} = v_free + M⁻¹ Hᵀ p, q_{k+1} = q_k + h((1−θ) v_k + θ v_{k+1}), records,
                 impacts, contact memory

`run_steps` runs them for a range of steps with the packed forces (the whole run is one
compiled call, whichever solver iparams names), plus an `extra` force (the step-wise loop that
calls back a Python `applied_force` runs it one step a call with that force). The data are named
tuples: `Model` (the packed scene, built by `_model_and_work` in moreau_jean.py), `Work` (the
contacts' memory and the step's kinematics), `Records` (the run's rows, `new_records`; the run goes
in windows of rows, moreau_jean_records.Window) and `Scratch` (the step's temporaries, allocated once
per call of the loop, so that a step allocates nothing). `_run` unpacks them once; the step's
functions take the arrays they use and count no references (`_jit.jit_borrowing`), and the step
itself (step_arrays and the step functions it calls once) is inlined into run_arrays
(`_jit.jit_inline`): a call passes each array as ~8 words on the stack, and those pushes were
most of a one-contact step (docs/performance.md).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .. import _jit
from .._jit import jit, jit_borrowing


_inlined = _jit.jit_inline  # the small per-contact helpers, compiled into the step's functions
from ..model.contact_kernels import (C_LINE_PX, C_LINE_PY, C_NX, C_NY, C_OBSTACLE_START_VX, C_OBSTACLE_START_VY,
                                      C_OBSTACLE_VX, C_OFF_AX, C_OFF_AY, C_RADIUS_A, C_RADIUS_B, C_SURFACE_VELOCITY,
                                      C_MOTION, KIND_FIXED_VERTEX_ON_EDGE, KIND_VERTEX_ON_EDGE,
                                      KIND_DISK_ON_DISK, KIND_DISK_ON_LINE, KIND_DISK_ON_SEGMENT, obstacle_velocity,
                                      vertex_cone_margin)
from ..model.forces import accumulate_forces
from .carved import carve_zeros
from ..model.joints import ROWS_PER_JOINT, jointed_dofs
from ..model.motion import NOW_END, NOW_VELOCITY, evaluate_motions
from ..model.packing import (C_MU_D, C_MU_S, C_RESTITUTION, CI_BODY_A, CI_BODY_B, CI_KIND,
                             contact_kinematics, drive_contacts, row_dot)
from ..solvers.kernels import carve, carve_matrix, solver_scratch, takes_block_sparse
from .joint_step import (constrained_delassus, held_contact_rows, joint_operators, joint_views, project_onto_joints,
                         project_positions)
from ..solvers.two_coefficient import (KERNEL_SOLVED, STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS,
                                       pgs_scratch_sizes, two_coefficient_by_group, two_coefficient_into)

# Gaps below a picometre count as touching: a contact placed exactly on a line computes a gap
# of a few ulps either side of zero, and must not be left out of the step for that.
ACTIVATION_ROUNDOFF = 1e-12
# A persistent contact's gap below this many ulps of the largest coordinate is round-off.
GAP_ROUNDOFF_ULPS = 64.0
# Multiple of h² |g̈| within which a closed contact's gap counts as closed (persistence_margin).
PERSISTENCE_FACTOR = 4.0
# The broad phase runs when the scene lists more contacts between circles (disks, vertices,
# edges, segments) than this: for a few, sorting the circles costs more than the kinematics it
# saves (measured: row of two balls 3.7 → 3.6 µs).
BROAD_PHASE_MIN_PAIRS = 8
# The broad phase tests each listed circle pair when there are at most this many per circle
# (cheaper than sorting and looking pairs up: a tower of 5 boxes lists 320 on 40 circles), and
# sweeps the sorted circles beyond (a heap of 50 boxes lists ~40 000 on ~400).
PAIRS_PER_CIRCLE_TESTED = 16
# Added to every disk's reach in the broad phase (m): contacts placed exactly touching.
BROAD_PHASE_SLACK = 1e-9
# A contact closes "with approaching velocity" when u_N before the step is below this.
IMPACT_VELOCITY_TOL = 1e-9
# Run status codes.
RUN_OK, RUN_SOLVER_FAILED, RUN_NONFINITE, RUN_STOPPED, RUN_BAD_GEOMETRY = 0, 1, 2, 3, 4
# A disk's contact deeper than the disk (its centre past the obstacle): the body passed through it within
# a step far too long for its speed — never a result to report as ok.
RUN_PASSED_THROUGH = 6
# (set from Python, between windows: a stop condition held at a kept sample)
RUN_STOPPED_BY_CONDITION = 5
# (never leaves _run) a step's dense W does not fit the per-run scratch: _run grows it and goes on
# from that step (Scratch.need: the step, its active contacts)
RUN_SCRATCH_SHORT = 7
# (never leaves moreau_jean._advance) a contact became a candidate with every column of the records
# taken (Records.column): the window widens its records and goes on from that step
RUN_RECORDS_SHORT = 8
# Slots of the int64 `counters` record.
(K_DONE, K_STATUS, K_FAIL_STEP, K_N_IMPACTS, K_SOLVES, K_INCONSISTENT, K_ITERATIONS, K_SOLVER_STATUS,
 K_FAIL_CONTACT, K_FALLBACKS, K_REPEATED) = range(11)
N_COUNTERS = 11
# The solver's work counters a repeated step adds again (_repeat_period).
REPEATED_COUNTERS = (K_SOLVES, K_INCONSISTENT, K_ITERATIONS, K_FALLBACKS)
# Float parameters: h, θ, γ (activation), the time origin t0, solver rtol, and the step index
# of row 0 of the out arrays (a run goes in windows of rows: a step's time is t0 + (k0 + k) h
# whichever window or restart it falls in, so a restarted run repeats the very same floats).
# Int parameters: solver code, max iterations, stop contact (−1: none), and whether the step
# map is the same at every time (no force or obstacle that changes with t alone: a state the
# step leaves unchanged is then kept for the rest of the window without solving — _run).
P_H, P_THETA, P_GAMMA, P_T0, P_RTOL, P_K0, P_H_GRID = range(7)
N_PARAMS = 7
I_SOLVER, I_MAX_ITER, I_STOP, I_TIME_INVARIANT = range(4)
N_IPARAMS = 4
# Slots of the per-run scratch (step_scratch): the step's temporaries, allocated once per call of
# run_steps instead of ~40 small arrays per step. Sized by the scene's contacts: pgs's (the
# block-sparse W, the sign iteration, the sweeps and the fallback to Lemke) for any active set;
# the dense W (lemke, enum, joints) for SCRATCH_W_CONTACTS active contacts, grown by _run when a step
# has more (RUN_SCRATCH_SHORT: rare, and outside the borrowing step); the dense solvers' for
# groups of up to SCRATCH_SOLVER_CONTACTS (a larger group's split allocates its own:
# two_coefficient._by_group_split).
S_FLOATS, S_STATES, S_W, S_SOLVER_FLOATS, S_SOLVER_INTS, S_SPARSE_INTS, S_SPARSE_FLOATS, S_NEED = range(8)
SCRATCH_W_CONTACTS = 64
SCRATCH_SOLVER_CONTACTS = 16
# Slots of the `model` tuple appended for driven obstacles and bodies (model/motion.py): the packed
# motions (table, times, values), their evaluation at the current step (NOW_* columns), the driven
# bodies (body, motion) and each one's placement the motion displaces (origin: q0 − d(t0)).
M_MOTIONS, M_MOTION_TIMES, M_MOTION_VALUES, M_MOTION_NOW, M_DRIVEN, M_DRIVEN_ORIGIN = range(12, 18)
# Slots of the joints (joint_step.py) in the model, work and out tuples, after the others (one
# array each: every array of a tuple costs reference counting in every step, joints or not).
# model: the joint table (model/joints.pack_joints); work: the joints' buffer (joint_step.joint_views).
M_JOINTS = 18
WORK_JOINTS = 11
# out: each step's joint impulses (rows × 2 per joint).
O_JOINT_IMPULSE = 10
# out: each contact's column of the per-contact records + 1 (0: none yet), and at [n_contacts] the
# columns given (new_records, _open_column).
O_COLUMN = 11
# The loop's data, by name (as MuJoCo's mjModel / mjData): the packed scene (moreau_jean._model_and_work),
# the contacts' per-step memory and scratch, and the run's records (moreau_jean_records.Window). The
# step's functions take the arrays they use, unpacked once per run (run_arrays): a tuple of arrays
# passed across a call costs an atomic reference count per array, and that was most of a step
# (~300 a step for one contact, measured with gdb on NRT_incref).
Model = namedtuple("Model", "minv weight contacts contact_index force_table force_index force_times force_values "
                   "disks disk_body pair_keys pair_contact motions motion_times motion_values motion_now driven "
                   "driven_origin joints")
Work = namedtuple("Work", "gaps drifts hn ht active was_closed grazing slip_sign v_free a_free candidate joint_buffer")
Records = namedtuple("Records", "q v p_normal p_tangent slip states impact_t impact_step impact_contact counters "
                     "joint_impulse column")
# A step's temporaries (step_scratch), allocated once per call of the loop; need: the step and
# active contacts a RUN_SCRATCH_SHORT asks room for.
# kept, kept_pose: the broad phase's kept list (broad_candidates), rebuilt at each call's first step.
Scratch = namedtuple("Scratch", "floats states W solver_floats solver_ints sparse_ints sparse_floats need kept "
                     "kept_pose")


def new_records(n_dof, n_contacts, rows, impacts, joint_rows, columns=None):
    """Records of `rows` steps (rows + 1 states), room for `impacts` impacts, `joint_rows` joint
    impulses a step: the one constructor of the loop's `out` (moreau_jean_records.Window, adaptive).

    The per-contact records (p_normal, p_tangent, slip, states) have a column per contact that has
    been a candidate (its kinematics computed) since they were zeroed, given when it first is one
    (_open_column; Records.column maps contacts to columns): `columns` of them, at most
    n_contacts. None: every contact its own column in order, given now (the error control's
    short windows). A contact without a column has the records of one out of reach: 0, 0, the
    belt's −surface velocity, open — 340 found candidates of a tower of 5 boxes, 12 to 36 of
    which ever come near, wrote 54 MB of such rows in a 5000-step run."""
    width = n_contacts if columns is None else min(columns, n_contacts)
    per_step, f, i = (rows, width), np.float64, np.int64  # one buffer a dtype (integrators/carved.py)
    records = Records(*carve_zeros((((rows + 1, n_dof), f), ((rows + 1, n_dof), f), (per_step, f), (per_step, f),
                                    (per_step, f), (per_step, i), ((impacts,), f), ((impacts,), i), ((impacts,), i),
                                    ((N_COUNTERS,), i), ((rows, joint_rows), f), ((n_contacts + 1,), i))))
    if columns is None:
        records.column[:n_contacts] = np.arange(1, n_contacts + 1)
        records.column[n_contacts] = n_contacts
    return records


@_inlined
def _open_column(i, k, table, out):
    """Give contact i, a candidate at step k for the first time since the records were zeroed, the
    next column of the records (Records.column: its column + 1; at [n_contacts] the columns given),
    its rows before k those of a contact out of reach (as finish_arrays wrote them for it before);
    False when every column is taken (RUN_RECORDS_SHORT)."""
    column, n_contacts = out.column, table.shape[0]
    given = column[n_contacts]
    if given == out.p_normal.shape[1]:
        return False
    column[i], column[n_contacts] = given + 1, given + 1
    for r in range(k):
        out.p_normal[r, given], out.p_tangent[r, given] = 0.0, 0.0
        out.slip[r, given], out.states[r, given] = -table[i, C_SURFACE_VELOCITY], 0
    return True


@_inlined
def _obstacle_velocity(table, hn, ht, i, at_start):
    """(w_N, w_T) of contact i's obstacle: its velocity at the step's start (for the start velocity
    v_k) or end (for v_{k+1}), along n and t, plus a belt's surface velocity."""
    c = C_OBSTACLE_START_VX if at_start else C_OBSTACLE_VX
    return obstacle_velocity(hn[i, 0], hn[i, 1], ht[i, 0], ht[i, 1], table[i, c], table[i, c + 1],
                             table[i, C_SURFACE_VELOCITY])


@_inlined
def relative_normal_velocity(table, hn, ht, index, i, x, at_start):
    """u_N of contact i at the scene velocity x: H_N x less the obstacle's normal velocity."""
    return row_dot(hn, index, i, x) - _obstacle_velocity(table, hn, ht, i, at_start)[0]


@_inlined
def relative_slip_velocity(table, hn, ht, index, i, x, at_start):
    """u_T of contact i at the scene velocity x: H_T x less the obstacle's (and a belt's) tangential velocity."""
    return row_dot(ht, index, i, x) - _obstacle_velocity(table, hn, ht, i, at_start)[1]


@jit
def persistence_margin(h, drift, free_acceleration):
    """How far a closed contact's gap may open and the contact still count as closed.

    The velocity-level law with start-of-step Jacobians lets a loaded contact's gap wander by the
    change one step of its acceleration causes, h² |g̈| — and the Jacobian's turn within the step
    (h² |Ḣ_N v|) moves it by as much again each step (a ladder's top on its wall: +1.5 mm/s of
    normal velocity while loaded, at h = 1 ms). Keeping such a contact in the step costs nothing
    when it truly separates: the gap-keeping law u_N ≥ −g/h then leaves it without impulse.
    """
    return PERSISTENCE_FACTOR * h * h * (abs(drift) + abs(free_acceleration)) + ACTIVATION_ROUNDOFF


@jit_borrowing
def _disk_reach(h, q, v, disks, disk_body, x, y, reach, turn):
    """World centres of the disks and how far each can reach this step (radius + h · speed);
    turn: scratch for each body's (cos θ, sin θ), computed once for all of its circles."""
    for body in range(q.shape[0] // 3):
        turn[2 * body], turn[2 * body + 1] = math.cos(q[3 * body + 2]), math.sin(q[3 * body + 2])
    for d in range(disks.shape[0]):
        ox, oy = disks[d, 0], disks[d, 1]
        if disk_body[d] < 0:  # a fixed circle (a segment, a segment's end)
            x[d], y[d], reach[d] = ox, oy, disks[d, 2] + BROAD_PHASE_SLACK
            continue
        j = 3 * disk_body[d]
        c, s = turn[2 * disk_body[d]], turn[2 * disk_body[d] + 1]
        x[d] = q[j] + c * ox - s * oy
        y[d] = q[j + 1] + s * ox + c * oy
        # the fastest point of the circle: an edge's end turns faster than its middle
        lever = math.sqrt(ox * ox + oy * oy) + disks[d, 2]
        speed = math.sqrt(v[j] * v[j] + v[j + 1] * v[j + 1]) + abs(v[j + 2]) * lever
        reach[d] = disks[d, 2] + h * speed + BROAD_PHASE_SLACK


@_inlined
def _in_reach(x, y, reach, da, db):
    """Whether circles da and db can meet this step (their centres within both reaches, per axis)."""
    both = reach[da] + reach[db]
    return abs(x[db] - x[da]) <= both and abs(y[db] - y[da]) <= both


@_inlined
def _first_at_least(keys, key):
    """The first position of the sorted keys holding key or more (np.searchsorted's left side,
    inlined: most circle pairs in reach — a vertex on a vertex, an edge on an edge — join no
    contact, and the call cost more than the search)."""
    lo, hi = 0, keys.shape[0]
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo


@jit
def broad_phase(h, q, v, disks, disk_body, pair_keys, pair_contact, was_closed, candidate):
    """Mark the contacts that can act this step: the contacts closed last step, those outside the
    broad phase (on lines: lines_in_reach), and those whose two feature circles
    (packing.pack_disk_pairs) are within their reach. With few listed pairs per circle (a tower,
    a row of dominoes) each listed pair is tested; otherwise the circles are swept and pruned
    (_sweep_and_prune, O(circles log circles + pairs in reach)). Both mark the same contacts."""
    n = disks.shape[0]
    x, y, reach, turn = np.empty(n), np.empty(n), np.empty(n), np.empty(q.shape[0])
    _disk_reach(h, q, v, disks, disk_body, x, y, reach, turn)
    for i in range(candidate.shape[0]):
        candidate[i] = 1
    if pair_keys.shape[0] <= PAIRS_PER_CIRCLE_TESTED * n:
        _listed_pairs_in_reach(x, y, reach, pair_keys, pair_contact, was_closed, candidate)
        return
    along, across = (y, x) if np.max(y) - np.min(y) > np.max(x) - np.min(x) else (x, y)
    _sweep_and_prune(along, across, reach, np.argsort(along), disk_body, pair_keys, pair_contact, was_closed,
                     candidate)


@_inlined  # into its one caller: a dispatcher of its own would optimise its code again there
def _mark_candidates(h, q, v, disks, disk_body, pair_keys, pair_contact, was_closed, candidate, room):
    """broad_phase, its few-pairs-per-circle test (a tower, a row of dominoes) in the step's
    scratch `room` when its 3 floats a circle and one a dof fit there: broad_phase's four
    arrays a step and the reference counts of its call were ~1 µs of a tower's step."""
    n = disks.shape[0]
    if pair_keys.shape[0] > PAIRS_PER_CIRCLE_TESTED * n or 3 * n + q.shape[0] > room.shape[0]:
        broad_phase(h, q, v, disks, disk_body, pair_keys, pair_contact, was_closed, candidate)
        return
    x, at = carve(room, 0, n)
    y, at = carve(room, at, n)
    reach, at = carve(room, at, n)
    turn, at = carve(room, at, q.shape[0])
    _disk_reach(h, q, v, disks, disk_body, x, y, reach, turn)
    for i in range(candidate.shape[0]):
        candidate[i] = 1
    _listed_pairs_in_reach(x, y, reach, pair_keys, pair_contact, was_closed, candidate)


@jit_borrowing
def _listed_pairs_in_reach(x, y, reach, pair_keys, pair_contact, was_closed, candidate):
    """Mark each listed circle pair's contact that was closed or is in reach (key: a n + b, sorted:
    a found by stepping up, not by a division per pair — 320 divisions were ~1 µs of a tower's step)."""
    n = x.shape[0]
    da = 0
    for j in range(pair_contact.shape[0]):
        while pair_keys[j] >= (da + 1) * n:
            da += 1
        i = pair_contact[j]
        candidate[i] = 1 if was_closed[i] or _in_reach(x, y, reach, da, pair_keys[j] - da * n) else 0


@jit_borrowing
def _sweep_and_prune(along, across, reach, order, disk_body, pair_keys, pair_contact, was_closed, candidate):
    """Mark the contacts closed last step and those of the circle pairs in reach: the circles in
    `order` along the axis they spread most on (a tower's y, a row's x: the same pairs are found
    on either, the widest prunes most), each swept against the next ones until out of reach; one
    body's own circles skipped (no contact joins them: packing)."""
    n = along.shape[0]
    for j in range(pair_contact.shape[0]):
        candidate[pair_contact[j]] = was_closed[pair_contact[j]]
    widest = 0.0  # circles of different sizes (a vertex, an edge): stop the sweep at the widest's reach
    for d in range(n):
        widest = max(widest, reach[d])
    for a in range(n):
        da = order[a]
        for b in range(a + 1, n):
            db = order[b]
            if along[db] - along[da] > reach[da] + widest:
                break
            if disk_body[da] == disk_body[db] or not _in_reach(along, across, reach, da, db):
                continue
            key = min(da, db) * n + max(da, db)
            j = _first_at_least(pair_keys, key)
            while j < pair_keys.shape[0] and pair_keys[j] == key:
                candidate[pair_contact[j]] = 1
                j += 1


@jit_borrowing
def lines_in_reach(reach_time, q, v, table, index, was_closed, candidate):
    """Leave out of this step a point or disk of a body on a line (infinite: not among the broad
    phase's circles) that cannot enter the step: the body's centre farther from the line than the
    disk's lever and radius plus what its fastest point and the line close in `reach_time`
    (γ h: the activation test's predicted gap, bounded below without the kinematics). A contact
    closed in the last step always enters the kinematics (its persistence margin)."""
    for i in range(table.shape[0]):
        if index[i, CI_KIND] != KIND_DISK_ON_LINE or was_closed[i]:
            continue
        if _line_clearance(reach_time, q, v, table, index, i) > ACTIVATION_ROUNDOFF + BROAD_PHASE_SLACK:
            candidate[i] = 0


@_inlined
def _line_clearance(reach_time, q, v, table, index, i):
    """How far contact i's point or disk (on a line) stays from the line in `reach_time` at most:
    its body's centre from the line, less the point's lever and radius and what its fastest point
    and the line close in that time (lines_in_reach leaves it out when this is positive)."""
    j = 3 * index[i, CI_BODY_A]
    ox, oy = table[i, C_OFF_AX], table[i, C_OFF_AY]
    wx, wy = table[i, C_OBSTACLE_START_VX], table[i, C_OBSTACLE_START_VY]
    lever = math.sqrt(ox * ox + oy * oy)
    centre = table[i, C_NX] * (q[j] - table[i, C_LINE_PX]) + table[i, C_NY] * (q[j + 1] - table[i, C_LINE_PY])
    speed = math.sqrt(v[j] * v[j] + v[j + 1] * v[j + 1]) + abs(v[j + 2]) * lever + math.sqrt(wx * wx + wy * wy)
    return centre - lever - table[i, C_RADIUS_A] - reach_time * speed


# The broad phase's kept list (Verlet lists with a skin, as molecular dynamics' neighbour lists and
# Box2D's fat boxes; broad_candidates): the circle pairs and points on lines within the skin s of
# each other at a build, tested each step until some body may have moved by BROAD_PHASE_REBUILD s.
# s: this fraction of the scene's smallest circle radius > 0 (half its shortest edge, its smallest
# disk), small against every shape, so that the list holds few more pairs than touch.
BROAD_PHASE_SKIN = 0.2
# Below 1/2 (the proof in broad_candidates' docstring): the rest is room for round-off.
BROAD_PHASE_REBUILD = 0.45


@_inlined  # into its one caller: a dispatcher of its own would optimise its code again there
def kept_sizes(n_dof, n_circles, n_contacts, n_pairs):
    """The sizes of Scratch.kept (ints: the counts of kept pairs and lines, a (contact, circle,
    circle) triple per kept pair, the kept lines' contacts, then at _visits_at the step's visit
    list: its count, −1 while none, and its contacts) and Scratch.kept_pose (floats, _pose_views:
    q at the build, each body's lever, the skin and 1 once built; then the circles' centres, the q
    they were placed at and each circle's lever); none without a broad phase."""
    if n_pairs <= BROAD_PHASE_MIN_PAIRS:
        return 0, 0
    return 3 + 3 * n_pairs + 2 * n_contacts, 2 * n_dof + n_dof // 3 + 2 + 3 * n_circles


@_inlined
def _visits_at(pair_keys, table):
    """Where Scratch.kept's visit list starts (kept_sizes): its count (−1: none), then its contacts."""
    return 2 + 3 * pair_keys.shape[0] + table.shape[0]


@_inlined
def _visits(kept, pair_keys, table):
    """(count, start) of the contacts the step's loops visit: the kept list's visit list while it has
    one (_keep_near: every contact that may be a candidate or has a column of the records until the
    next build, in order — the others are out of reach, with zero rows and no records to write),
    else every contact (start −1)."""
    if kept.shape[0] > 0:
        at = _visits_at(pair_keys, table)
        if kept[at] >= 0:
            return kept[at], at + 1
    return table.shape[0], -1


# broad_candidates' outcomes: no kept list (the whole broad phase ran), a kept list built at this
# step, the kept list of an earlier step reused.
NO_KEPT_LIST, KEPT_LIST_BUILT, KEPT_LIST_REUSED = 0, 1, 2


@_inlined
def _pose_views(kept_pose, n_dof, n_circles):
    """(the build's pose block: q, levers, skin, built flag; the circles' centres x, y; the q
    they were placed at; each circle's lever |o| + r) — views of Scratch.kept_pose."""
    pose, at = carve(kept_pose, 0, n_dof + n_dof // 3 + 2)
    x, at = carve(kept_pose, at, n_circles)
    y, at = carve(kept_pose, at, n_circles)
    placed, at = carve(kept_pose, at, n_dof)
    levers, at = carve(kept_pose, at, n_circles)
    return pose, x, y, placed, levers


@_inlined  # into its one caller: a dispatcher of its own would optimise its code again there
def _circles_now(h, q, v, disks, disk_body, x, y, placed, levers, reach, turn):
    """_disk_reach's centres and reach, the very same floats, on the kept list's memory: a body's
    circles are placed again only when its q changed since they were (a body at rest costs no
    cos, sin), and each circle's lever is the one _keep_near computed. turn: scratch of 4 floats a
    body (cos θ, sin θ, |v|, whether it moved)."""
    for body in range(q.shape[0] // 3):
        j, at = 3 * body, 4 * body
        moved = q[j] != placed[j] or q[j + 1] != placed[j + 1] or q[j + 2] != placed[j + 2]
        turn[at + 3] = 1.0 if moved else 0.0
        if moved:
            turn[at], turn[at + 1] = math.cos(q[j + 2]), math.sin(q[j + 2])
            placed[j], placed[j + 1], placed[j + 2] = q[j], q[j + 1], q[j + 2]
        turn[at + 2] = math.sqrt(v[j] * v[j] + v[j + 1] * v[j + 1])
    for d in range(disks.shape[0]):
        if disk_body[d] < 0:  # a fixed circle (placed by _keep_near)
            reach[d] = disks[d, 2] + BROAD_PHASE_SLACK
            continue
        j, at = 3 * disk_body[d], 4 * disk_body[d]
        if turn[at + 3] != 0.0:
            ox, oy, c, s = disks[d, 0], disks[d, 1], turn[at], turn[at + 1]
            x[d] = q[j] + c * ox - s * oy
            y[d] = q[j + 1] + s * ox + c * oy
        speed = turn[at + 2] + abs(v[j + 2]) * levers[d]
        reach[d] = disks[d, 2] + h * speed + BROAD_PHASE_SLACK


@jit_borrowing
def broad_candidates(h, gamma, q, v, disks, disk_body, pair_keys, pair_contact, table, index, was_closed, candidate,
                     room, kept, kept_pose, column):
    """The step's broad phase: the candidates _mark_candidates and lines_in_reach(γ h) mark, tested
    by the same tests but only over a kept list (Scratch.kept; _keep_near builds it, with the
    visit list of the contacts that may be candidates or have a column of the records `column`)
    while no body has moved past the skin since its build (empty kept, or no room: those two on
    every contact). Returns NO_KEPT_LIST, KEPT_LIST_BUILT or KEPT_LIST_REUSED.

    Why the kept list holds every candidate: a circle at offset o (lever ℓ = |o| + r ≤ L, its
    body's lever) has its centre within D = |Δx|₁ + |Δθ| L of where it was at the build, and its
    reach this step is r + h (|v| + |ω| ℓ) + slack ≤ r + S + slack with S = h max(1, |γ|)
    (|v|₁ + |ω| L). While D + S ≤ BROAD_PHASE_REBUILD s < s/2 for every body (_past_skin), two
    circles in reach now (per axis, centres within the sum of reaches) had centres within
    rₐ + r_b + 2 slack + s at the build: the build's test with each reach r + s/2 + slack kept
    them. A point on a fixed line: its clearance now (_line_clearance, γ h) is at least its
    clearance at the build less D + S, so one that cleared s/2 at the build is still out; a
    driven or moving line's contacts are always kept. A contact closed at the build is kept, and
    one closes later only as a candidate, hence kept. Each step then marks exactly what the
    full broad phase marks, less the vertex–edge pairs whose cone rule rejects them at every pose
    until the next build (_out_of_cone_until_rebuilt: the kernel would give them an infinite gap
    and zero rows, the records of a contact out of reach — finish_arrays), so results are
    unchanged (tests/integrators/test_broad_phase.py)."""
    n, n_dof = disks.shape[0], q.shape[0]
    if kept.shape[0] == 0 or kept_pose.shape[0] == 0 or n + 4 * (n_dof // 3) > room.shape[0]:
        _mark_candidates(h, q, v, disks, disk_body, pair_keys, pair_contact, was_closed, candidate, room)
        lines_in_reach(h * abs(gamma), q, v, table, index, was_closed, candidate)
        if kept.shape[0] > 0:
            kept[_visits_at(pair_keys, table)] = -1  # no visit list: the step visits every contact
        return NO_KEPT_LIST
    pose, x, y, placed, levers = _pose_views(kept_pose, n_dof, n)
    outcome = KEPT_LIST_REUSED
    if pose[n_dof + n_dof // 3 + 1] == 0.0 or _past_skin(h * max(1.0, abs(gamma)), q, v, pose):
        _keep_near(q, v, disks, disk_body, pair_keys, pair_contact, table, index, was_closed, candidate, kept,
                   kept_pose, column)
        outcome = KEPT_LIST_BUILT
    reach, at = carve(room, 0, n)
    turn, at = carve(room, at, 4 * (n_dof // 3))
    _circles_now(h, q, v, disks, disk_body, x, y, placed, levers, reach, turn)
    for k in range(kept[0]):
        i = kept[2 + 3 * k]
        candidate[i] = 1 if was_closed[i] or _in_reach(x, y, reach, kept[3 + 3 * k], kept[4 + 3 * k]) else 0
    lines = 2 + 3 * pair_keys.shape[0]
    for k in range(kept[1]):
        i = kept[lines + k]
        out = not was_closed[i] and (_line_clearance(h * abs(gamma), q, v, table, index, i)
                                     > ACTIVATION_ROUNDOFF + BROAD_PHASE_SLACK)
        candidate[i] = 0 if out else 1
    return outcome


@_inlined
def _past_skin(step, q, v, kept_pose):
    """Whether some body may have moved its circles, since the kept list's build, plus what one
    step of `step` seconds adds at its velocity, by more than BROAD_PHASE_REBUILD × the skin
    (|Δx|₁ + |Δθ| L + step (|v|₁ + |ω| L), L its lever). A non-finite state rebuilds."""
    n_dof = q.shape[0]
    n_bodies = n_dof // 3
    limit = BROAD_PHASE_REBUILD * kept_pose[n_dof + n_bodies]
    for b in range(n_bodies):
        j, lever = 3 * b, kept_pose[n_dof + b]
        moved = abs(q[j] - kept_pose[j]) + abs(q[j + 1] - kept_pose[j + 1]) + abs(q[j + 2] - kept_pose[j + 2]) * lever
        moved += step * (abs(v[j]) + abs(v[j + 1]) + abs(v[j + 2]) * lever)
        if not moved <= limit:
            return True
    return False


@jit
def _keep_near(q, v, disks, disk_body, pair_keys, pair_contact, table, index, was_closed, candidate, kept, kept_pose,
               column):
    """Build the kept list at pose q (broad_candidates): the listed circle pairs within each
    other's radius + s/2 + slack or closed (found as the broad phase finds pairs in reach:
    each tested, or swept), and the points on lines closed, on a driven or moving line, or
    within s/2 of it, less the vertex–edge pairs the cone rule rejects until the next build
    (_out_of_cone_until_rebuilt); every other such contact's candidate set to 0 until the next
    build (the contacts the broad phase never leaves out: 1); and the visit list (_visits): those
    marked and those with a column of the records (`column`, Records.column). Records the pose,
    the levers and the skin."""
    n, n_dof = disks.shape[0], q.shape[0]
    pose, x, y, placed, levers = _pose_views(kept_pose, n_dof, n)
    skin = _skin_and_levers(disks, disk_body, table, index, pose, n_dof)
    reach, turn = np.empty(n), np.empty(n_dof)
    _disk_reach(0.0, q, v, disks, disk_body, x, y, reach, turn)  # the centres; reach r + slack
    for d in range(n):
        reach[d] += 0.5 * skin
        levers[d] = math.sqrt(disks[d, 0] * disks[d, 0] + disks[d, 1] * disks[d, 1]) + disks[d, 2]  # as _disk_reach
    for j in range(n_dof):
        placed[j] = q[j]  # where the centres now are (_circles_now places a body again when it moves)
    for i in range(candidate.shape[0]):
        candidate[i] = 1
    if pair_keys.shape[0] <= PAIRS_PER_CIRCLE_TESTED * n:
        _listed_pairs_in_reach(x, y, reach, pair_keys, pair_contact, was_closed, candidate)
    else:
        along, across = (y, x) if np.max(y) - np.min(y) > np.max(x) - np.min(x) else (x, y)
        _sweep_and_prune(along, across, reach, np.argsort(along), disk_body, pair_keys, pair_contact, was_closed,
                         candidate)
    count, da = 0, 0
    for j in range(pair_keys.shape[0]):
        while pair_keys[j] >= (da + 1) * n:
            da += 1
        if candidate[pair_contact[j]] and _out_of_cone_until_rebuilt(pair_contact[j], q, table, index, was_closed,
                                                                     pose, skin):
            candidate[pair_contact[j]] = 0
        if candidate[pair_contact[j]]:
            kept[2 + 3 * count], kept[3 + 3 * count], kept[4 + 3 * count] = pair_contact[j], da, pair_keys[j] - da * n
            count += 1
    kept[0], lines, count = count, 2 + 3 * pair_keys.shape[0], 0
    for i in range(table.shape[0]):
        if index[i, CI_KIND] != KIND_DISK_ON_LINE:
            continue
        still = (table[i, C_MOTION] < 0.0 and table[i, C_OBSTACLE_START_VX] == 0.0
                 and table[i, C_OBSTACLE_START_VY] == 0.0)
        if still and not was_closed[i] and (_line_clearance(0.0, q, v, table, index, i) - 0.5 * skin
                                            > ACTIVATION_ROUNDOFF + BROAD_PHASE_SLACK):
            candidate[i] = 0
        else:
            kept[lines + count] = i
            count += 1
    kept[1] = count
    at, count = _visits_at(pair_keys, table), 0
    for i in range(table.shape[0]):
        if candidate[i] or column[i] > 0:
            kept[at + 1 + count] = i
            count += 1
    kept[at] = count
    for d in range(n_dof):
        pose[d] = q[d]
    pose[n_dof + n_dof // 3 + 1] = 1.0


# Added to the bound on a kept vertex–edge pair's cone margin (_out_of_cone_until_rebuilt): the
# round-off of a few products of unit vectors, with room to spare.
CONE_MARGIN_SLACK = 1e-9


@_inlined
def _out_of_cone_until_rebuilt(i, q, table, index, was_closed, pose, skin):
    """Whether contact i, a vertex on an edge not closed, is rejected by the kernel's cone rule at
    every pose the kept list built at q serves (vertex_cone_margin < 0): its margin now below
    minus the most the two bodies can turn before a rebuild — |Δθ| L ≤ BROAD_PHASE_REBUILD s for
    a body of lever L (_past_skin), and the margin moves by at most the relative turn. Such a
    pair (a box's corner beside the side of the box it sits on) would get an infinite gap and
    zero rows every step: left out, it costs no kinematics and no column of the records."""
    kind = index[i, CI_KIND]
    if was_closed[i] or (kind != KIND_VERTEX_ON_EDGE and kind != KIND_FIXED_VERTEX_ON_EDGE):
        return False
    point, edge = index[i, CI_BODY_A], index[i, CI_BODY_B]
    if kind == KIND_FIXED_VERTEX_ON_EDGE:  # (a segment's end on body a's edge)
        point, edge = -1, index[i, CI_BODY_A]
    n_dof = q.shape[0]
    turn = 0.0
    for body in (point, edge):
        if body >= 0:
            lever = pose[n_dof + body]
            turn += BROAD_PHASE_REBUILD * skin / lever if lever > 0.0 else math.inf
    return vertex_cone_margin(table[i], point, edge, q) < -turn - CONE_MARGIN_SLACK


@jit_borrowing
def _skin_and_levers(disks, disk_body, table, index, kept_pose, n_dof):
    """The skin s (BROAD_PHASE_SKIN × the smallest circle radius > 0; 0 without one: rebuilt
    whenever anything moves), written after each body's lever L (the farthest reach of its
    circles, |o| + r, and of its points on lines, |o|, from its centre) in kept_pose; returns s."""
    n_bodies = n_dof // 3
    for b in range(n_bodies):
        kept_pose[n_dof + b] = 0.0
    smallest = math.inf
    for d in range(disks.shape[0]):
        r = disks[d, 2]
        if r > 0.0:
            smallest = min(smallest, r)
        if disk_body[d] >= 0:
            at = n_dof + disk_body[d]
            kept_pose[at] = max(kept_pose[at], math.sqrt(disks[d, 0] ** 2 + disks[d, 1] ** 2) + r)
    for i in range(table.shape[0]):
        if index[i, CI_KIND] == KIND_DISK_ON_LINE:
            at = n_dof + index[i, CI_BODY_A]
            kept_pose[at] = max(kept_pose[at], math.sqrt(table[i, C_OFF_AX] ** 2 + table[i, C_OFF_AY] ** 2))
    skin = BROAD_PHASE_SKIN * smallest if smallest < math.inf else 0.0
    kept_pose[n_dof + n_bodies] = skin
    return skin


@jit_borrowing
def pass_through_depth(table, index, i):
    """How deep contact i may go before its body has passed through the obstacle: the disk's radius
    (of two disks the smaller; a disk on a body's corner, the disk's); 0 — no such check — for a
    point on a line, whose depth has no scale."""
    kind = index[i, CI_KIND]
    if kind == KIND_DISK_ON_LINE or kind == KIND_DISK_ON_SEGMENT:
        return table[i, C_RADIUS_A]
    if kind == KIND_DISK_ON_DISK:
        ra, rb = table[i, C_RADIUS_A], table[i, C_RADIUS_B]
        return max(ra, rb) if min(ra, rb) == 0.0 else min(ra, rb)
    return 0.0


@jit
def geometry_failure(na, n_contacts, counters):
    """The run status of begin_step's failure code na < 0 (−1 − i: contact i's normal undefined;
    −1 − n_contacts − i: contact i passed through), the contact booked in the counters;
    RUN_RECORDS_SHORT for records_full(n_contacts) (no column left for a new candidate)."""
    code = -1 - na
    if code >= 2 * n_contacts:
        return RUN_RECORDS_SHORT
    counters[K_FAIL_CONTACT] = code % n_contacts
    return RUN_BAD_GEOMETRY if code < n_contacts else RUN_PASSED_THROUGH


@jit
def begin_step(params, qk, vk, f, model, work, k, out):
    """begin_arrays of step k on the model, work and out tuples (the step-wise loop's entry)."""
    return begin_arrays(params, qk, vk, f, model.minv, model.contacts, model.contact_index, model.disks,
                        model.disk_body, model.pair_keys, model.pair_contact, model.joints, work.joint_buffer,
                        work.gaps, work.drifts, work.hn, work.ht, work.active, work.was_closed, work.v_free,
                        work.a_free, work.candidate, np.empty(0), np.empty(0, dtype=np.int64), np.empty(0), k, out)


@_inlined
def records_full(n_contacts):
    """begin_arrays' code when a candidate finds every column of the records taken (geometry_failure
    reads it as RUN_RECORDS_SHORT): below every geometry failure's."""
    return -1 - 2 * n_contacts


@_inlined
def begin_arrays(params, qk, vk, f, minv, table, index, disks, disk_body, pair_keys, pair_contact, joints,
                 joint_buffer, gaps, drifts, hn, ht, active, was_closed, v_free, a_free, candidate, room, kept,
                 kept_pose, k, out):
    """Free velocity, contact kinematics and the active set of step k; returns na (< 0: geometry_failure's
    code: −1 − i, contact i's normal undefined; −1 − n_contacts − i, contact i passed through;
    records_full: no column of the records `out` left for a new candidate, _open_column).
    room: floats the broad phase may use (the step's scratch, free until the solve; empty: none);
    kept, kept_pose: its kept list (Scratch's; empty: none, every contact tested)."""
    h, gamma = params[P_H], params[P_GAMMA]
    for d in range(qk.shape[0]):
        a_free[d] = minv[d] * f[d]
        v_free[d] = vk[d] + h * a_free[d]
    if joints.shape[0] > 0:
        _joints_begin(qk, minv, joints, joint_buffer, v_free, a_free)
    broad = pair_keys.shape[0] > BROAD_PHASE_MIN_PAIRS  # enough disk pairs for sorting to pay
    outcome = NO_KEPT_LIST
    if broad:
        outcome = broad_candidates(h, gamma, qk, vk, disks, disk_body, pair_keys, pair_contact, table, index,
                                   was_closed, candidate, room, kept, kept_pose, out.column)
    # on a reused kept list, its visit list (every other contact out of reach since the build, its
    # rows zeroed by the build's step, which visits every contact)
    n_visits, start = _visits(kept, pair_keys, table) if outcome == KEPT_LIST_REUSED else (table.shape[0], -1)
    na = 0
    for e in range(n_visits):
        i = kept[start + e] if start >= 0 else e
        if broad and not candidate[i]:
            # out of reach this step: no kinematics. An infinite gap comes with zero rows (a pair
            # the kernel rejects gets them too): rows already zeroed are not written again.
            # (nor its gap and drift: only an active contact's drift is read)
            if gaps[i] != math.inf:
                for d in range(6):  # element by element: a row slice costs more, per listed contact
                    hn[i, d] = 0.0
                    ht[i, d] = 0.0
                gaps[i], drifts[i] = math.inf, 0.0
            continue
        if out.column[i] == 0 and not _open_column(i, k, table, out):
            return records_full(table.shape[0])  # (the step is run again once the records are wider)
        gap, drift = contact_kinematics(table, index, i, qk, vk, hn[i], ht[i])
        if math.isnan(gap):
            return -1 - i
        depth = pass_through_depth(table, index, i)
        if depth > 0.0 and gap < -depth:
            return -1 - table.shape[0] - i
        gaps[i], drifts[i] = gap, drift
        if gap == math.inf:  # not the touching pair of features (zero rows): never active
            continue
        predicted = gap + gamma * h * relative_normal_velocity(table, hn, ht, index, i, vk, True)
        margin = ACTIVATION_ROUNDOFF
        if was_closed[i]:
            # the grid's h, not a shortened last step's: a contact resting at the gap the full steps
            # left it stays closed through the last step (else the ball falls for that step)
            margin = persistence_margin(params[P_H_GRID], drift, row_dot(hn, index, i, a_free))
        if predicted <= margin:
            active[na] = i
            na += 1
    return na


@_inlined
def _block_entries(hn, ht, index, i, j, minv):
    """(NN, NT, TN, TT): the 2×2 block (N, T)ᵢ M⁻¹ (N, T)ⱼᵀ of the Delassus matrix, over the bodies
    both contacts touch. Scalar loops, no row views and inlined: a pile's ~800 blocks per step cost
    ~110 ns each through views and calls (issue 26), most of the step."""
    nn, nt, tn, tt = 0.0, 0.0, 0.0, 0.0
    for side_i in range(2):
        body = index[i, CI_BODY_A + side_i]
        if body < 0:
            continue
        for side_j in range(2):
            if index[j, CI_BODY_A + side_j] == body:
                for d in range(3):
                    w = minv[3 * body + d]
                    a_n, a_t = hn[i, 3 * side_i + d] * w, ht[i, 3 * side_i + d] * w
                    b_n, b_t = hn[j, 3 * side_j + d], ht[j, 3 * side_j + d]
                    nn += a_n * b_n
                    nt += a_n * b_t
                    tn += a_t * b_n
                    tt += a_t * b_t
    return nn, nt, tn, tt


@_inlined  # into its one caller: a dispatcher of its own would optimise its code again there
def _contacts_by_body(na, active, index, start, fill, members):
    """start, members: the active contacts (positions in `active`) touching each body, CSR
    (start: n_bodies + 1 entries, members: 2 na; fill: n_bodies + 1 entries of scratch)."""
    n_bodies = start.shape[0] - 1
    for b in range(n_bodies + 1):
        start[b] = 0
    for a in range(na):
        for side in range(2):
            body = index[active[a], CI_BODY_A + side]
            if body >= 0:
                start[body + 1] += 1
    for b in range(n_bodies):
        start[b + 1] += start[b]
    for b in range(n_bodies + 1):
        fill[b] = start[b]
    for a in range(na):
        for side in range(2):
            body = index[active[a], CI_BODY_A + side]
            if body >= 0:
                members[fill[body]] = a
                fill[body] += 1


@jit_borrowing
def delassus_blocks(na, minv, index, hn, ht, active, ints, floats):
    """The block-sparse Delassus matrix over the active contacts (solvers/delassus.py's block layout:
    indptr, indices, 2×2 blocks): a block for each pair of contacts sharing a body, so building
    it costs O(active contacts × contacts per body), not O(contacts²). Written into the scratch
    (ints, floats: S_SPARSE_INTS, S_SPARSE_FLOATS, sized by step_scratch for any active set):
    indptr first, then its work arrays, then the nnz columns; the blocks at the front of floats.
    Returns nnz (sparse_views carves the three). Borrowing: it allocates nothing."""
    n_bodies = minv.shape[0] // 3
    indptr, at = carve(ints, 0, na + 1)
    start, at = carve(ints, at, n_bodies + 1)
    fill, at = carve(ints, at, n_bodies + 1)
    members, at = carve(ints, at, 2 * na)
    seen, at = carve(ints, at, na)
    _contacts_by_body(na, active, index, start, fill, members)
    indptr[0] = 0
    for sweep in range(2):  # count, then fill
        for a in range(na):
            seen[a] = -1
        for a in range(na):
            n = 0
            for side in range(2):
                body = index[active[a], CI_BODY_A + side]
                for m in range(start[body] if body >= 0 else 0, start[body + 1] if body >= 0 else 0):
                    b = members[m]
                    if seen[b] != a:
                        seen[b] = a
                        if sweep == 1:
                            k = indptr[a] + n
                            ints[at + k] = b
                            floats[4 * k], floats[4 * k + 1], floats[4 * k + 2], floats[4 * k + 3] = _block_entries(
                                hn, ht, index, active[a], active[b], minv)
                        n += 1
            if sweep == 0:
                indptr[a + 1] = indptr[a] + n
    return indptr[na]


@_inlined
def sparse_views(na, n_bodies, nnz, ints, floats):
    """(indptr, indices, blocks): the views of the block-sparse W delassus_blocks wrote."""
    at = na + 1 + 2 * (n_bodies + 1) + 3 * na
    return ints[:na + 1], ints[at:at + nnz], floats[:4 * nnz].reshape((nnz, 2, 2))


@_inlined  # into its one caller: a dispatcher of its own would optimise its code again there
def _sparse_capacity(index, n_bodies):
    """The most blocks the block-sparse W of any set of active contacts can hold: per contact,
    the contacts touching its bodies."""
    touching = np.zeros(n_bodies, dtype=np.int64)
    for i in range(index.shape[0]):
        for side in range(2):
            if index[i, CI_BODY_A + side] >= 0:
                touching[index[i, CI_BODY_A + side]] += 1
    blocks = 0
    for i in range(index.shape[0]):
        for side in range(2):
            if index[i, CI_BODY_A + side] >= 0:
                blocks += touching[index[i, CI_BODY_A + side]]
    return blocks


@jit
def assemble(params, na, qk, vk, model, work, W, q_step, guess, mu_s, mu_d, closing, resting):
    """assemble_arrays on the model and work tuples (the step-wise loop's entry)."""
    assemble_arrays(params, na, qk, vk, model.minv, model.contacts, model.contact_index, model.joints,
                    work.joint_buffer, work.gaps, work.hn, work.ht, work.active, work.was_closed, work.grazing,
                    work.slip_sign, work.v_free, W, q_step, guess, mu_s, mu_d, closing, resting)


@_inlined
def assemble_arrays(params, na, qk, vk, minv, table, index, joints, joint_buffer, gaps, hn, ht, active, was_closed,
                    grazing, slip_sign, v_free, W, q_step, guess, mu_s, mu_d, closing, resting):
    """The step problem u = W p + q_step over the active contacts, with slip guesses and μs, μd;
    `resting` is 1 for a contact loaded in the previous step or not slipping at the step's start."""
    h = params[P_H]
    # A gap of a few ulps of the positions is no gap: closing it would ask a velocity round-off/h
    # that a body's other contacts cannot all follow (a statically indeterminate body would slip).
    gap_roundoff = 1.0
    for d in range(vk.shape[0]):
        gap_roundoff = max(gap_roundoff, abs(qk[d]))
    gap_roundoff *= GAP_ROUNDOFF_ULPS * 2.220446049250313e-16
    # A contact starts the step at rest when its slip velocity is round-off of the body speeds
    rest_tol = 1e-12
    for d in range(vk.shape[0]):
        rest_tol = max(rest_tol, 1e-9 * abs(vk[d]))
    for a in range(na):
        i = active[a]
        for b in range(na if W.shape[0] > 0 else 0):  # dense W: for lemke and enum
            j = active[b]
            W[2 * a, 2 * b], W[2 * a, 2 * b + 1], W[2 * a + 1, 2 * b], W[2 * a + 1, 2 * b + 1] = _block_entries(
                hn, ht, index, i, j, minv)
        q_step[2 * a + 1] = relative_slip_velocity(table, hn, ht, index, i, v_free, False)
        # only a contact at rest — loaded in the previous step, or not slipping at the step's start —
        # is held by a search over admissible splits (sticking.py); one grazing a rolling
        # neighbour without load keeps the solver's answer (the search costs milliseconds there)
        loaded = was_closed[i] and not grazing[i]
        at_rest = abs(relative_slip_velocity(table, hn, ht, index, i, vk, True)) <= rest_tol
        resting[a] = 1.0 if loaded or at_rest else 0.0
        mu_s[a], mu_d[a] = table[i, C_MU_S], table[i, C_MU_D]
        if was_closed[i]:
            # A persistent contact may close an open gap, not only keep u_N ≥ 0: the Jacobian
            # turns with the body within the step, so a purely velocity-level law lets the gap
            # creep open by O(h) per unit time. u_N ≥ −g/h for g > 0 removes the creep; a
            # penetration (g < 0) is not pushed out, which would inject energy after impacts.
            closing[a] = (gaps[i] if gaps[i] > gap_roundoff else 0.0) / h  # the part asking to close a gap
            q_step[2 * a] = relative_normal_velocity(table, hn, ht, index, i, v_free, False) + closing[a]
            guess[a] = slip_sign[i]
        else:
            closing[a] = 0.0
            u_n = relative_normal_velocity(table, hn, ht, index, i, vk, True)
            q_step[2 * a] = (relative_normal_velocity(table, hn, ht, index, i, v_free, False)
                             + table[i, C_RESTITUTION] * min(u_n, 0.0))
            # a closing contact slides the way it arrives
            u_t = relative_slip_velocity(table, hn, ht, index, i, vk, True)
            guess[a] = 0.0 if abs(u_t) < 1e-12 else math.copysign(1.0, u_t)
    if joints.shape[0] > 0:
        _joints_delassus(na, active, hn, ht, index, minv, joints, joint_buffer, W)


@jit
def crossing_offset(g, u, a, h):
    """Root τ of g + u τ + ½ a τ² nearest 0 within [−h, 2h] (0 if none): where in the step the
    gap crossed zero. The contact may enter the problem a little before (predicted gap) or after
    (closing late in the previous step) the crossing."""
    best = math.nan
    r1 = math.nan
    r2 = math.nan
    if abs(a) > 1e-14:
        disc = u * u - 2.0 * a * g
        if disc >= 0.0:
            sq = math.sqrt(disc)
            r1 = (-u - sq) / a
            r2 = (-u + sq) / a
    elif u != 0.0:
        r1 = -g / u
    for r in (r1, r2):
        if not math.isnan(r) and -h <= r <= 2 * h:
            if math.isnan(best) or abs(r) < abs(best):
                best = r
    return 0.0 if math.isnan(best) else best


@jit_borrowing
def _record_impact(k, t, i, u_before, gap, acceleration, params, iparams, impact_t, impact_step, impact_contact,
                   counters):
    """Book contact i's impact in step k (its gap at the step's start, u_N before, normal
    acceleration); True when it is the stop contact's."""
    n = counters[K_N_IMPACTS]
    if n >= impact_t.shape[0]:  # the record is full: the impact still acts, unrecorded
        return i == iparams[I_STOP]
    impact_t[n] = t + crossing_offset(gap, u_before, acceleration, params[P_H])
    impact_step[n] = k
    impact_contact[n] = i
    counters[K_N_IMPACTS] = n + 1
    return i == iparams[I_STOP]


@jit
def finish_step(k, params, iparams, na, p, u, states, qk, vk, model, work, out):
    """finish_arrays on the model, work and out tuples (the step-wise loop's entry)."""
    return finish_arrays(k, params, iparams, na, p, u, states, qk, vk, model.minv, model.contacts,
                         model.contact_index, model.pair_keys, model.joints, work.joint_buffer, work.gaps,
                         work.drifts, work.hn, work.ht, work.active, work.was_closed, work.grazing, work.slip_sign,
                         work.v_free, work.a_free, work.candidate, out, np.empty(0, dtype=np.int64))


@_inlined
def _end_velocity(na, p, minv, index, hn, ht, active, v_free, v_next):
    """v_{k+1} = v_free + M⁻¹ Hᵀ p (element by element: a slice copy needs numba's NRT)."""
    for d in range(v_next.shape[0]):
        v_next[d] = v_free[d]
    for a in range(na):
        i = active[a]
        for side in range(2):
            body = index[i, CI_BODY_A + side]
            if body >= 0:
                for d in range(3):
                    v_next[3 * body + d] += minv[3 * body + d] * (hn[i, 3 * side + d] * p[2 * a]
                                                                  + ht[i, 3 * side + d] * p[2 * a + 1])


@_inlined
def _open_records(k, n_visits, start, kept, broad, table, index, gaps, hn, ht, grazing, candidate, v_next, out):
    """Step k's records of the visited contacts (_visits) as if none acted — p = 0, open, the slip
    at v_{k+1} — and their grazing cleared: finish_arrays then writes the active ones' over them."""
    column, p_normal, p_tangent, slip, state_rec = out.column, out.p_normal, out.p_tangent, out.slip, out.states
    for e in range(n_visits):
        i = kept[start + e] if start >= 0 else e
        grazing[i] = 0
        c = column[i] - 1  # contact i's records' column (−1: none, never a candidate)
        if c < 0:
            continue  # no records to write: those of a contact out of reach (_open_column)
        p_normal[k, c] = 0.0
        p_tangent[k, c] = 0.0
        state_rec[k, c] = 0
        if (not broad or candidate[i]) and gaps[i] != math.inf:
            slip[k, c] = relative_slip_velocity(table, hn, ht, index, i, v_next, False)
        else:  # a contact out of reach, or not the touching pair, has zero rows: only the belt's
            slip[k, c] = -table[i, C_SURFACE_VELOCITY]  # surface velocity is left (its ±0 not v's)


@_inlined
def finish_arrays(k, params, iparams, na, p, u, states, qk, vk, minv, table, index, pair_keys, joints, joint_buffer,
                  gaps, drifts, hn, ht, active, was_closed, grazing, slip_sign, v_free, a_free, candidate, out, kept):
    """End-of-step state, the step's records (`out`: Records), impacts and the contacts' memory;
    returns a run status (RUN_OK, RUN_STOPPED at the stop contact's first impact, RUN_NONFINITE).
    kept: Scratch.kept (empty: none) — its visit list holds every contact with a column or that
    may be a candidate (_visits): the others have no records to write and no memory to change."""
    q, v, p_normal, p_tangent, state_rec = out.q, out.v, out.p_normal, out.p_tangent, out.states
    impact_t, impact_step, impact_contact = out.impact_t, out.impact_step, out.impact_contact
    counters, joint_impulse, column = out.counters, out.joint_impulse, out.column  # (column: _open_column)
    h, theta = params[P_H], params[P_THETA]
    t = step_time(params, k)
    v_next = v[k + 1]
    _end_velocity(na, p, minv, index, hn, ht, active, v_free, v_next)
    jointed = joints.shape[0] > 0
    if jointed:
        _joints_finish(v_next, minv, joints, joint_buffer, joint_impulse[k])
    finite = True
    for d in range(qk.shape[0]):
        q[k + 1, d] = qk[d] + h * ((1.0 - theta) * vk[d] + theta * v_next[d])
        finite = finite and math.isfinite(q[k + 1, d]) and math.isfinite(v_next[d])
    if jointed and finite:
        _joints_project(q[k + 1], na, states, active, hn, ht, index, minv, joints, joint_buffer, params, gaps, drifts,
                        a_free, table, v_next)
    status = RUN_OK
    broad = pair_keys.shape[0] > BROAD_PHASE_MIN_PAIRS  # as begin_arrays' broad phase
    n_visits, start = _visits(kept, pair_keys, table)
    _open_records(k, n_visits, start, kept, broad, table, index, gaps, hn, ht, grazing, candidate, v_next, out)
    for a in range(na):
        i = active[a]
        c = column[i] - 1  # (an active contact is a candidate: it has its column)
        p_normal[k, c], p_tangent[k, c], state_rec[k, c] = p[2 * a], p[2 * a + 1], states[a]
        if states[a] == STATE_OPEN and was_closed[i] and _rides_the_gap(i, params, gaps, drifts, hn, ht, a_free,
                                                                        table, index, v_next):
            grazing[i] = 1  # no force this step (reported open), yet not apart: no impact on return
        slip_sign[i] = 1.0 if states[a] == STATE_SLIP_PLUS else (-1.0 if states[a] == STATE_SLIP_MINUS else 0.0)
    for e in range(n_visits):
        i = kept[start + e] if start >= 0 else e
        if broad and not candidate[i]:
            continue  # no impulse, not grazing, and not closed before (a closed contact is a candidate)
        closed = p_normal[k, column[i] - 1] > 0.0
        if closed and not was_closed[i]:
            # An impact: a contact that was apart closes with approaching velocity. A persistent
            # contact that rode its gap without impulse for a step stays closed (grazing), so it
            # is not one.
            u_before = relative_normal_velocity(table, hn, ht, index, i, vk, True)
            if u_before < -IMPACT_VELOCITY_TOL and _record_impact(
                    k, t, i, u_before, gaps[i], row_dot(hn, index, i, a_free) + drifts[i], params, iparams, impact_t,
                    impact_step, impact_contact, counters):
                status = RUN_STOPPED
        was_closed[i] = 1 if closed or grazing[i] else 0
    if not finite:
        return RUN_NONFINITE
    return status


@jit
def _joint_state(minv, table, buffer):
    """(dofs, slot, J, C, A⁺, W_c, λ_free) of the joints: the jointed dofs and the buffer's views."""
    n_dof = minv.shape[0]
    dofs, slot = jointed_dofs(table, n_dof)
    J, C, A_pinv, WC, free = joint_views(buffer, ROWS_PER_JOINT * table.shape[0], n_dof, dofs.shape[0])
    return dofs, slot, J, C, A_pinv, WC, free


@jit
def _joints_begin(qk, minv, table, buffer, v_free, a_free):
    """The joints at q_k (J, A⁺, W_c) and the free velocity and acceleration projected onto them."""
    dofs, _, J, C, A_pinv, WC, free = _joint_state(minv, table, buffer)
    joint_operators(qk, minv, table, dofs, J, C, A_pinv, WC)
    project_onto_joints(v_free, minv, J, A_pinv, free)
    project_onto_joints(a_free, minv, J, A_pinv, np.empty(J.shape[0]))


@jit
def _joints_delassus(na, active, hn, ht, index, minv, table, buffer, W):
    """W = H W_c Hᵀ over the active contacts: the contacts' Delassus matrix with the joints."""
    _, slot, _, _, _, WC, _ = _joint_state(minv, table, buffer)
    constrained_delassus(na, active, hn, ht, index, minv, slot, WC, W)


@jit
def _joints_finish(v_next, minv, table, buffer, impulse):
    """v_{k+1} projected onto the joints (J v_{k+1} = 0) and the step's joint impulses recorded."""
    _, _, J, _, A_pinv, _, free = _joint_state(minv, table, buffer)
    project_onto_joints(v_next, minv, J, A_pinv, impulse)
    for r in range(impulse.shape[0]):
        impulse[r] += free[r]


@jit
def _joints_project(q_next, na, states, active, hn, ht, index, minv, table, buffer, params, gaps, drifts, a_free,
                    contacts, v_next):
    """q_{k+1} projected back onto the joints' positions C(q) = 0 (their drift stays round-off),
    the contacts that held this step — loaded, or unloaded but still at their obstacle
    (_rides_the_gap) — kept where they are."""
    _, slot, J, C, _, _, _ = _joint_state(minv, table, buffer)
    held, held_bodies = np.empty((2 * na, 6)), np.empty((2 * na, 2), dtype=np.int64)
    touching = np.zeros(na, dtype=np.int64)
    for a in range(na):
        if states[a] == STATE_OPEN and _rides_the_gap(active[a], params, gaps, drifts, hn, ht, a_free, contacts,
                                                      index, v_next):
            touching[a] = 1
    n_held = held_contact_rows(na, active, states, touching, hn, ht, index, slot, held, held_bodies)
    project_positions(q_next, minv, table, J, C, held, held_bodies, n_held)


@jit_borrowing
def _rides_the_gap(i, params, gaps, drifts, hn, ht, a_free, table, index, v_next):
    """A persistent contact that got no impulse but ends the step within h² |g̈| of
    its obstacle: it carries no force (reported open) but has not come apart, so its next loaded
    step is no impact — near a lift-off the normal force fades and such steps alternate with
    loaded ones."""
    h = params[P_H]
    # within one step's worth of its acceleration, h² |g̈|: a hop of a ball at rest is longer
    margin = h * h * (abs(drifts[i]) + abs(row_dot(hn, index, i, a_free))) + ACTIVATION_ROUNDOFF
    return gaps[i] + h * relative_normal_velocity(table, hn, ht, index, i, v_next, False) <= margin


@_inlined
def _warm_start(k, na, active, was_closed, p_normal, p_tangent, column, p):
    """The previous step's impulses of the contacts that stay closed (pgs starts from p; column:
    Records.column, a closed contact's records in column[i] − 1)."""
    if k == 0:
        return
    for a in range(na):
        i = active[a]
        if was_closed[i]:
            p[2 * a], p[2 * a + 1] = p_normal[k - 1, column[i] - 1], p_tangent[k - 1, column[i] - 1]


@jit
def step_scratch(solver_code, model, dense_contacts):
    """The per-run scratch (Scratch) for the packed scene `model`: pgs's for any active set, the
    dense W for max(SCRATCH_W_CONTACTS, dense_contacts) active contacts (or the scene's)."""
    n_contacts, n_bodies = model.contacts.shape[0], model.minv.shape[0] // 3
    sparse = takes_block_sparse(solver_code) and model.joints.shape[0] == 0  # as solve_arrays
    dense = 0 if sparse else min(n_contacts, max(SCRATCH_W_CONTACTS, dense_contacts))
    blocks = _sparse_capacity(model.contact_index, n_bodies) if sparse else 0
    if sparse:
        n_floats, n_ints = pgs_scratch_sizes(n_contacts)
        solver_floats, solver_ints = np.empty(n_floats), np.empty(n_ints, dtype=np.int64)
    else:
        solver_floats, solver_ints = solver_scratch(min(n_contacts, SCRATCH_SOLVER_CONTACTS))
    sparse_ints = 2 * n_bodies + 4 * n_contacts + 3 + blocks if sparse else 0
    n_kept, n_pose = kept_sizes(model.minv.shape[0], model.disks.shape[0], n_contacts, model.pair_keys.shape[0])
    return Scratch(np.empty(11 * n_contacts), np.empty(n_contacts, dtype=np.int64), np.empty(4 * dense * dense),
                   solver_floats, solver_ints, np.empty(sparse_ints, dtype=np.int64), np.empty(4 * blocks),
                   np.zeros(2, dtype=np.int64), np.zeros(n_kept, dtype=np.int64), np.zeros(n_pose))


@_inlined
def _dense_matrix(scratch_w, m, sparse):
    """The step's dense W (m × m, every entry written by assemble): a view of the scratch (that
    holds it: step_arrays asked _run for room first), empty for pgs."""
    return carve_matrix(scratch_w, 0, 0 if sparse else m, 0 if sparse else m)[0]


@_inlined
def _dense_fits(solver_code, na, joints, scratch_w):
    """True when the step's W (dense for lemke, enum and joints; block-sparse for pgs) fits the scratch."""
    sparse = takes_block_sparse(solver_code) and joints.shape[0] == 0
    return sparse or 4 * na * na <= scratch_w.shape[0]


@_inlined
def solve_arrays(solver_code, k, params, iparams, na, qk, vk, minv, table, index, joints, joint_buffer, gaps, hn, ht,
                 active, was_closed, grazing, slip_sign, v_free, p_normal, p_tangent, column, counters, scratch, p, u,
                 states):
    """assemble + the two-coefficient kernel into p, u, states (step_impulses' views), in the
    per-run scratch (Scratch); p_normal, p_tangent, column: the records (the warm start).
    Returns the kernel status. Borrowing: it allocates nothing (the dense W fits: step_arrays)."""
    s_floats, s_w = scratch.floats, scratch.W
    s_sparse_ints, s_sparse_floats = scratch.sparse_ints, scratch.sparse_floats
    s_solver_floats, s_solver_ints = scratch.solver_floats, scratch.solver_ints
    m = 2 * na
    # pgs sweeps the block-sparse W; lemke, enum need it dense, and so do joints (W_c couples a cluster)
    sparse = takes_block_sparse(solver_code) and joints.shape[0] == 0
    W = _dense_matrix(s_w, m, sparse)
    q_step, at = carve(s_floats, 0, m)
    guess, at = carve(s_floats, at, na)
    mu_s, at = carve(s_floats, at, na)
    mu_d, at = carve(s_floats, at, na)
    closing, at = carve(s_floats, at, na)
    resting, at = carve(s_floats, at, na)
    assemble_arrays(params, na, qk, vk, minv, table, index, joints, joint_buffer, gaps, hn, ht, active, was_closed,
                    grazing, slip_sign, v_free, W, q_step, guess, mu_s, mu_d, closing, resting)
    for r in range(m):
        p[r], u[r] = 0.0, 0.0
    for a in range(na):
        states[a] = 0
    _warm_start(k, na, active, was_closed, p_normal, p_tangent, column, p)
    if sparse:
        nnz = delassus_blocks(na, minv, index, hn, ht, active, s_sparse_ints, s_sparse_floats)
        indptr, indices, blocks = sparse_views(na, minv.shape[0] // 3, nnz, s_sparse_ints, s_sparse_floats)
        status, solves, iterations, consistent, fallbacks = two_coefficient_into(  # (pgs_scratch_sizes: it fits)
            solver_code, W, indptr, indices, blocks, q_step, mu_s, mu_d, guess, closing, resting, params[P_RTOL],
            iparams[I_MAX_ITER], p, u, states, s_solver_floats, s_solver_ints)
    else:  # lemke, enum: one group of coupled contacts at a time (their cost grows with the group)
        status, solves, iterations, consistent, fallbacks = two_coefficient_by_group(
            solver_code, W, q_step, mu_s, mu_d, guess, closing, resting, params[P_RTOL], iparams[I_MAX_ITER], p, u,
            states, s_solver_floats, s_solver_ints)
    counters[K_SOLVES] += solves
    counters[K_ITERATIONS] += iterations
    counters[K_FALLBACKS] += fallbacks
    if status == KERNEL_SOLVED and not consistent:
        counters[K_INCONSISTENT] += 1
    return status


@_inlined
def step_impulses(na, s_floats, s_states):
    """(p, u, states) of a step with na active contacts: views of the scratch after the step
    problem's 7 na floats (q_step, guess, μs, μd, closing, resting; solve_arrays carves them)."""
    return s_floats[7 * na: 9 * na], s_floats[9 * na: 11 * na], s_states[:na]


@_inlined
def step_arrays(solver_code, k, f, params, iparams, model, work, out, scratch):
    """One whole step with generalised force f on the named data (Model, Work, Records, Scratch);
    returns a run status (the solver read from its code at run time). Inlined into run_arrays, as
    are begin_arrays, solve_arrays and finish_arrays: no call passes the tuples' arrays."""
    m, w, o = model, work, out
    qk, vk = o.q[k], o.v[k]
    if m.motions.shape[0] > 0:  # (a scene without driven obstacles or bodies skips their calls)
        drive_arrays(k, params, m.contacts, m.motions, m.motion_times, m.motion_values, m.motion_now)
    na = begin_arrays(params, qk, vk, f, m.minv, m.contacts, m.contact_index, m.disks, m.disk_body, m.pair_keys,
                      m.pair_contact, m.joints, w.joint_buffer, w.gaps, w.drifts, w.hn, w.ht, w.active, w.was_closed,
                      w.v_free, w.a_free, w.candidate, scratch.floats, scratch.kept, scratch.kept_pose, k, o)
    if na < 0:
        return geometry_failure(na, m.contacts.shape[0], o.counters)
    if m.driven.shape[0] > 0:
        hold_driven_arrays(m.driven, m.motion_now, w.v_free)
    p, u, states = step_impulses(na, scratch.floats, scratch.states)  # (empty without contacts)
    if not _dense_fits(solver_code, na, m.joints, scratch.W):
        scratch.need[0], scratch.need[1] = k, na  # _run grows the scratch and redoes this step
        return RUN_SCRATCH_SHORT
    if na > 0:
        status = solve_arrays(
            solver_code, k, params, iparams, na, qk, vk, m.minv, m.contacts, m.contact_index, m.joints,
            w.joint_buffer, w.gaps, w.hn, w.ht, w.active, w.was_closed, w.grazing, w.slip_sign, w.v_free,
            o.p_normal, o.p_tangent, o.column, o.counters, scratch, p, u, states)
        if status != KERNEL_SOLVED:
            o.counters[K_SOLVER_STATUS] = status
            return RUN_SOLVER_FAILED
    status = finish_arrays(k, params, iparams, na, p, u, states, qk, vk, m.minv, m.contacts, m.contact_index,
                           m.pair_keys, m.joints, w.joint_buffer, w.gaps, w.drifts, w.hn, w.ht, w.active,
                           w.was_closed, w.grazing, w.slip_sign, w.v_free, w.a_free, w.candidate, o, scratch.kept)
    if m.driven.shape[0] > 0:
        place_driven_arrays(k, m.driven, m.driven_origin, m.motion_now, o.q, o.v)
    return status


@jit
def drive_step(k, params, model):
    """drive_arrays on the model tuple (the step-wise loop's entry)."""
    drive_arrays(k, params, model.contacts, model.motions, model.motion_times, model.motion_values, model.motion_now)


@jit
def drive_arrays(k, params, table, motions, motion_times, motion_values, motion_now):
    """Step k's driven obstacles and bodies: the motions at its start and end (the compiled ones;
    the step-wise loop wrote the Python ones), the driven obstacles' contact rows moved there."""
    t = step_time(params, k)
    evaluate_motions(t, t + params[P_H], motions, motion_times, motion_values, motion_now)
    drive_contacts(table, motion_now)


@jit
def hold_driven_velocities(model, work):
    """hold_driven_arrays on the tuples (the step-wise loop's entry)."""
    hold_driven_arrays(model.driven, model.motion_now, work.v_free)


@jit
def hold_driven_arrays(driven, now, v_free):
    """A driven body's free velocity is its prescribed velocity at the step's end: with M⁻¹ = 0 no
    force or impulse changes it, so the contacts see it move as prescribed."""
    for r in range(driven.shape[0]):
        j, m = 3 * driven[r, 0], driven[r, 1]
        for d in range(3):
            v_free[j + d] = now[m, NOW_VELOCITY + d]


@jit
def place_driven_bodies(k, model, out):
    """place_driven_arrays on the tuples (the step-wise loop's entry)."""
    place_driven_arrays(k, model.driven, model.driven_origin, model.motion_now, out.q, out.v)


@jit
def place_driven_arrays(k, driven, origin, now, q, v):
    """A driven body's end-of-step state is its prescribed one (not the θ-method's quadrature of it)."""
    for r in range(driven.shape[0]):
        j, m = 3 * driven[r, 0], driven[r, 1]
        for d in range(3):
            q[k + 1, j + d] = origin[r, d] + now[m, NOW_END + d]
            v[k + 1, j + d] = now[m, NOW_VELOCITY + d]


@_inlined
def step_time(params, k):
    """t_k = t0 + (k0 + k) h: the start of row k's step, from the run's one origin."""
    return params[P_T0] + (params[P_K0] + k) * params[P_H]


@jit
def step_force(k, params, model, out, f):
    """f = weight + the packed forces at t_k + θh and (q_k, v_k)."""
    _packed_force(k, params, model.weight, model.force_table, model.force_index, model.force_times,
                  model.force_values, out.q, out.v, f)


@_inlined
def _packed_force(k, params, weight, ftable, findex, ftimes, fvalues, q, v, f):
    """step_force on the force arrays themselves (the whole-run loop unpacks them once)."""
    for d in range(f.shape[0]):
        f[d] = weight[d]
    t = params[P_T0] + ((params[P_K0] + k) + params[P_THETA]) * params[P_H]
    if ftable.shape[0] > 0:
        accumulate_forces(t, q[k], v[k], ftable, findex, ftimes, fvalues, f)


@_inlined
def end_of_step(k, status, counters):
    """Book step k's outcome in the counters (steps done; how and where the run ended)."""
    if status == RUN_OK or status == RUN_STOPPED:
        counters[K_DONE] = k + 1
    if status != RUN_OK:
        counters[K_STATUS] = status
        counters[K_FAIL_STEP] = k
    return status


@_inlined  # into run_steps: numba generates a callee's code again in each caller (a level: ~9 s of a cold compile)
def _run(solver_code, k_start, k_end, params, iparams, model, work, out, extra):
    """Steps k_start … k_end − 1 with the packed forces (+ `extra`): the whole run in one call."""
    # what the loop needs besides the tuples, allocated here: run_arrays counts no references
    f, ring = np.empty(model.minv.shape[0]), np.empty((3, 3, model.contacts.shape[0]))
    before = np.empty((3, len(REPEATED_COUNTERS)), dtype=np.int64)
    scratch = step_scratch(solver_code, model, 0)
    k = k_start
    while True:
        status = run_arrays(solver_code, k_start, k, k_end, params, iparams, extra, scratch, f, ring, before, model,
                            work, out)
        if status != RUN_SCRATCH_SHORT:
            return status  # (RUN_RECORDS_SHORT: the records are widened in Python, moreau_jean._advance)
        # a step with more active contacts than the dense W holds (lemke, enum, joints): room for
        # twice as many, and the step again from its start (its begin recomputes what it wrote)
        k = scratch.need[0]
        scratch = step_scratch(solver_code, model, 2 * scratch.need[1])


@jit_borrowing
def run_arrays(solver_code, k_start, k_first, k_end, params, iparams, extra, scratch, f, memory, before, model, work,
               out):
    """The loop over the steps k_first … k_end − 1 of the call that began at k_start, on the named
    data; f: the force's array, memory and before: the rest's ring (below). Returns a run status
    (RUN_SCRATCH_SHORT: the step scratch.need[0] needs a larger scratch, _run's)."""
    m, o = model, out
    # The contacts' memory after each of the last three steps and the solver's counters before
    # them (a ring by step): what _fixed_period compares — only where a rest can be repeated (not
    # a time-varying scene, nor the one-step calls of the step-wise loop).
    repeats = iparams[I_TIME_INVARIANT] != 0 and k_end - k_start > 2
    k = k_first
    while k < k_end:
        if repeats:
            for c in range(len(REPEATED_COUNTERS)):
                before[k % 3, c] = o.counters[REPEATED_COUNTERS[c]]
        _packed_force(k, params, m.weight, m.force_table, m.force_index, m.force_times, m.force_values, o.q, o.v, f)
        for d in range(extra.shape[0]):
            f[d] += extra[d]
        status = step_arrays(solver_code, k, f, params, iparams, model, work, out, scratch)
        if status == RUN_SCRATCH_SHORT or status == RUN_RECORDS_SHORT:
            return status  # (step k not done: counters[K_DONE] = k)
        if end_of_step(k, status, o.counters) != RUN_OK:
            return o.counters[K_STATUS]
        if repeats:
            k = _after_step(k, k_start, k_end, work, out, memory, before)
        k += 1
    return RUN_OK


@_inlined
def _after_step(k, k_start, k_end, work, out, memory, before):
    """The rest's bookkeeping after step k: the contacts' memory into the ring, and a rest found
    repeated to k_end (returns the last step so filled, else k)."""
    w, o = work, out
    for i in range(memory.shape[2]):
        memory[k % 3, 0, i], memory[k % 3, 1, i], memory[k % 3, 2, i] = w.was_closed[i], w.grazing[i], w.slip_sign[i]
    period = _fixed_period(k, k - k_start + 1, o.q, o.v, o.p_normal, o.p_tangent, memory) if k + 1 < k_end else 0
    if period > 0:
        return _repeat_period(k, k_end, period, o.q, o.v, o.p_normal, o.p_tangent, o.slip, o.states, o.joint_impulse,
                              o.counters, w.was_closed, w.grazing, w.slip_sign, memory, before)
    return k


@jit_borrowing
def _fixed_period(k, steps_here, q, v, p_normal, p_tangent, memory):
    """1 or 2 when the state step k leaves — q, v, the contacts' memory and the impulses the next
    step warm-starts from — is the one left by step k − 1 (a rest) or k − 2 (a two-step cycle of
    round-off, as a held body's v alternating between two values of 1e-18); else 0.

    The step map is a function of that state, the same at every t when iparams[I_TIME_INVARIANT]
    (no force that changes with time alone): every later step then repeats one of the last
    `period` steps bit for bit. Exact holds (no creep) reach such a state within a few steps."""
    for period in range(1, 3):
        if steps_here <= period:
            return 0
        same = True
        for d in range(q.shape[1]):
            if q[k + 1, d] != q[k + 1 - period, d] or v[k + 1, d] != v[k + 1 - period, d]:
                same = False
                break
        for c in range(p_normal.shape[1] if same else 0):  # the records' columns (new_records)
            if p_normal[k, c] != p_normal[k - period, c] or p_tangent[k, c] != p_tangent[k - period, c]:
                same = False
                break
        for i in range(memory.shape[2] if same else 0):  # every contact's memory
            for m in range(3):
                if memory[k % 3, m, i] != memory[(k - period) % 3, m, i]:
                    same = False
            if not same:
                break
        if same:
            return period
    return 0


@jit
def _repeat_period(k, k_end, period, q, v, p_normal, p_tangent, slip, state_rec, joint_impulse, counters, was_closed,
                   grazing, slip_sign, memory, before):
    """Rows k + 1 … k_end − 1 as the step `period` rows before each made them (state, records,
    the solver's counters, the memory left at the end); returns the last step so filled."""
    for r in range(k + 1, k_end):
        q[r + 1, :] = q[r + 1 - period]
        v[r + 1, :] = v[r + 1 - period]
        p_normal[r, :] = p_normal[r - period]
        p_tangent[r, :] = p_tangent[r - period]
        slip[r, :] = slip[r - period]
        state_rec[r, :] = state_rec[r - period]
        joint_impulse[r, :] = joint_impulse[r - period]
    for c in range(len(REPEATED_COUNTERS)):
        added = 0
        for j in range(k + 1 - period, k + 1):  # each repeated step adds what its original added
            after = counters[REPEATED_COUNTERS[c]] if j == k else before[(j + 1) % 3, c]
            n = (k_end - 1 - j) // period  # the later steps j + period, j + 2 period, ... < k_end
            added += n * (after - before[j % 3, c])
        counters[REPEATED_COUNTERS[c]] += added
    last = k_end - 1
    src = k - ((k - last) % period)  # the step of the last period that `last` repeats
    for i in range(memory.shape[2]):  # the memory the last filled step leaves: its original's
        was_closed[i], grazing[i], slip_sign[i] = memory[src % 3, 0, i], memory[src % 3, 1, i], memory[src % 3, 2, i]
    counters[K_REPEATED] += last - k
    counters[K_DONE] = k_end
    return last


# One compiled entry for every solver, which reads its code from iparams at run time: the three
# solvers then compile together into one loop (a one-way switch per step costs nothing measurable:
# rod, h = 1e-4, 12.67 / 12.34 / 50.46 µs per step against 12.48 / 12.35 / 49.24 with one literal
# entry per solver, back to back on a loaded machine), where one entry per solver compiled the
# whole tree once per solver — a test suite or `nonsmooth-rod compile` compiled it six times.
# The step-wise loop (a Python applied_force called back between steps) runs this same entry one
# step at a time with that force in `extra` (a second compiled entry inlined the whole step again
# and doubled the cold compile).
@jit
def run_steps(k_start, k_end, params, iparams, model, work, out, extra):
    """_run with the solver iparams[I_SOLVER] names; `extra`: a generalised force added to the
    packed forces at every step (empty: none)."""
    return _run(iparams[I_SOLVER], k_start, k_end, params, iparams, model, work, out, extra)


__all__ = ["Model", "Work", "Records", "Scratch", "begin_step", "assemble", "solve_arrays", "step_scratch",
           "geometry_failure", "finish_step", "step_force", "run_steps", "drive_step", "hold_driven_velocities",
           "place_driven_bodies", "crossing_offset", "ACTIVATION_ROUNDOFF"]
