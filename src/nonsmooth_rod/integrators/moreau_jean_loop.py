"""The one Moreau–Jean loop, on arrays: compiled with numba, or plain Python from the same source.

A step of size h from (q_k, v_k), for a packed scene (model.packing):

    begin_step   v_free = v_k + h M⁻¹ f; contact kinematics; the contacts that enter the step
    assemble     W = H M⁻¹ Hᵀ over the active contacts, q_step, the slip guesses, μs, μd
    (solve)      the exact two-coefficient law (solvers.two_coefficient.two_coefficient_kernel,
                 or the Python solve_two_coefficient for the QP solvers)
    finish_step  v_{k+1} = v_free + M⁻¹ Hᵀ p, q_{k+1} = q_k + h((1−θ) v_k + θ v_{k+1}), records,
                 impacts, contact memory

`run_steps` runs them for a range of steps with the packed forces (the whole run is one
compiled call, whichever solver iparams names); `compiled_step` runs one step with a force given by the caller (the step-wise
loop that calls back a Python `applied_force`). Arrays are grouped in three tuples so every
kernel compiles to one signature: model (scene), work (per-contact memory and scratch), out
(records). model and work are built by `_model_and_work` in moreau_jean.py, out by `Window` in
moreau_jean_records.py (the run in windows of rows).
"""
from __future__ import annotations

import math

import numpy as np

from .. import _jit
from .._jit import jit


def _inlined(function):
    """jit, inlined into its callers at numba's IR level: the per-step kernels pass the packed
    tuples (~30 arrays), and a call boundary costs ~300 ns of reference counting for them."""
    if not _jit.ENABLED:
        return function
    import numba

    return numba.njit(cache=True, inline="always")(function)
from ..model.forces import accumulate_forces
from ..model.joints import ROWS_PER_JOINT, jointed_dofs
from .joint_step import (constrained_delassus, held_contact_rows, joint_operators, joint_views, project_onto_joints,
                         project_positions)
from ..model.packing import (C_MU_D, C_MU_S, C_RESTITUTION, C_SURFACE_VELOCITY, CI_BODY_A, CI_KIND,
                             KIND_DISK_ON_DISK,
                             contact_kinematics, local_dot)
from ..solvers.kernels import SOLVER_ENUM, SOLVER_LEMKE, SOLVER_PGS
from ..solvers.two_coefficient import (KERNEL_SOLVED, STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS,
                                       two_coefficient_by_group, two_coefficient_kernel)

# Gaps below a picometre count as touching: a contact placed exactly on a line computes a gap
# of a few ulps either side of zero, and must not be left out of the step for that.
ACTIVATION_ROUNDOFF = 1e-12
# A persistent contact's gap below this many ulps of the largest coordinate is round-off.
GAP_ROUNDOFF_ULPS = 64.0
# Multiple of h² |g̈| within which a closed contact's gap counts as closed (persistence_margin).
PERSISTENCE_FACTOR = 4.0
# The broad phase runs when the scene lists more disk–disk contacts than this: for a few, sorting
# the disks costs more than the kinematics it saves (measured: row of two balls 3.7 → 3.6 µs).
BROAD_PHASE_MIN_PAIRS = 8
# Added to every disk's reach in the broad phase (m): contacts placed exactly touching.
BROAD_PHASE_SLACK = 1e-9
# A contact closes "with approaching velocity" when u_N before the step is below this.
IMPACT_VELOCITY_TOL = 1e-9
# Run status codes.
RUN_OK, RUN_SOLVER_FAILED, RUN_NONFINITE, RUN_STOPPED, RUN_BAD_GEOMETRY = 0, 1, 2, 3, 4
# (set from Python, between windows: a stop condition held at a kept sample)
RUN_STOPPED_BY_CONDITION = 5
# Slots of the int64 `counters` record.
(K_DONE, K_STATUS, K_FAIL_STEP, K_N_IMPACTS, K_SOLVES, K_INCONSISTENT, K_ITERATIONS, K_SOLVER_STATUS,
 K_FAIL_CONTACT, K_FALLBACKS) = range(10)
N_COUNTERS = 10
# Float parameters: h, θ, γ (activation), the time origin t0, solver rtol, and the step index
# of row 0 of the out arrays (a run goes in windows of rows: a step's time is t0 + (k0 + k) h
# whichever window or restart it falls in, so a restarted run repeats the very same floats).
# Int parameters: solver code, max iterations, stop contact (−1: none).
P_H, P_THETA, P_GAMMA, P_T0, P_RTOL, P_K0, P_H_GRID = range(7)
N_PARAMS = 7
I_SOLVER, I_MAX_ITER, I_STOP = range(3)
# Slots of the joints (joint_step.py) in the model, work and out tuples, after the others (one
# array each: every array of a tuple costs reference counting in every step, joints or not).
# model: the joint table (model/joints.pack_joints); work: the joints' buffer (joint_step.joint_views).
M_JOINTS = 12
WORK_JOINTS = 11
# out: each step's joint impulses (rows × 2 per joint).
O_JOINT_IMPULSE = 10


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


@jit
def _disk_reach(h, q, v, disks, disk_body, x, y, reach):
    """World centres of the disks and how far each can reach this step (radius + h · speed)."""
    for d in range(disks.shape[0]):
        j = 3 * disk_body[d]
        c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
        ox, oy = disks[d, 0], disks[d, 1]
        x[d] = q[j] + c * ox - s * oy
        y[d] = q[j + 1] + s * ox + c * oy
        speed = math.sqrt(v[j] * v[j] + v[j + 1] * v[j + 1]) + abs(v[j + 2]) * math.sqrt(ox * ox + oy * oy)
        reach[d] = disks[d, 2] + h * speed + BROAD_PHASE_SLACK


@jit
def broad_phase(h, q, v, disks, disk_body, pair_keys, pair_contact, was_closed, candidate):
    """Mark the disk–disk contacts that can act this step: sort the disks along x, and test only
    pairs whose centres are within their reach (sweep and prune), plus the contacts closed last
    step. O(disks log disks + pairs in reach), whatever the number of listed contacts."""
    n = disks.shape[0]
    x, y, reach = np.empty(n), np.empty(n), np.empty(n)
    _disk_reach(h, q, v, disks, disk_body, x, y, reach)
    for i in range(candidate.shape[0]):
        candidate[i] = was_closed[i]
    order = np.argsort(x)
    for a in range(n):
        da = order[a]
        for b in range(a + 1, n):
            db = order[b]
            if x[db] - x[da] > reach[da] + reach[db]:
                break
            if abs(y[db] - y[da]) > reach[da] + reach[db]:
                continue
            key = min(da, db) * n + max(da, db)
            j = np.searchsorted(pair_keys, key)
            while j < pair_keys.shape[0] and pair_keys[j] == key:
                candidate[pair_contact[j]] = 1
                j += 1


@_inlined
def begin_step(params, qk, vk, f, model, work):
    """Free velocity, contact kinematics and the active set; returns na (−1 − i: contact i has
    coincident disk centres)."""
    minv, table, index = model[0], model[2], model[3]  # only what is used: each array costs refcounting
    gaps, drifts, hn, ht, active, was_closed = work[0], work[1], work[2], work[3], work[4], work[5]
    v_free, a_free, candidate = work[8], work[9], work[10]
    h, gamma = params[P_H], params[P_GAMMA]
    for d in range(qk.shape[0]):
        a_free[d] = minv[d] * f[d]
        v_free[d] = vk[d] + h * a_free[d]
    if model[M_JOINTS].shape[0] > 0:  # (arrays, not the tuples: a call with them costs every step)
        _joints_begin(qk, minv, model[M_JOINTS], work[WORK_JOINTS], v_free, a_free)
    broad = model[10].shape[0] > BROAD_PHASE_MIN_PAIRS  # enough disk pairs for sorting to pay
    if broad:
        broad_phase(h, qk, vk, model[8], model[9], model[10], model[11], was_closed, candidate)
    na = 0
    for i in range(table.shape[0]):
        if broad and index[i, CI_KIND] == KIND_DISK_ON_DISK and not candidate[i]:
            gaps[i], drifts[i] = math.inf, 0.0  # out of reach this step: no kinematics
            hn[i, :] = 0.0
            ht[i, :] = 0.0
            continue
        gap, drift = contact_kinematics(table, index, i, qk, vk, hn[i], ht[i])
        if math.isnan(gap):
            return -1 - i
        gaps[i], drifts[i] = gap, drift
        predicted = gap + gamma * h * local_dot(hn[i], index, i, vk)
        margin = ACTIVATION_ROUNDOFF
        if was_closed[i]:
            # the grid's h, not a shortened last step's: a contact resting at the gap the full steps
            # left it stays closed through the last step (else the ball falls for that step)
            margin = persistence_margin(params[P_H_GRID], drift, local_dot(hn[i], index, i, a_free))
        if predicted <= margin:
            active[na] = i
            na += 1
    return na


@jit
def _block_product(row_i, index, i, row_j, j, minv):
    """row_i M⁻¹ row_jᵀ for two contacts' 6-entry rows: the bodies they share."""
    s = 0.0
    for side_i in range(2):
        body = index[i, CI_BODY_A + side_i]
        if body < 0:
            continue
        for side_j in range(2):
            if index[j, CI_BODY_A + side_j] == body:
                for d in range(3):
                    s += row_i[3 * side_i + d] * minv[3 * body + d] * row_j[3 * side_j + d]
    return s


@jit
def _fill_block(block, hn, ht, index, i, j, minv):
    """The 2×2 block (N, T)ᵢ M⁻¹ (N, T)ⱼᵀ of the Delassus matrix."""
    block[0, 0] = _block_product(hn[i], index, i, hn[j], j, minv)
    block[0, 1] = _block_product(hn[i], index, i, ht[j], j, minv)
    block[1, 0] = _block_product(ht[i], index, i, hn[j], j, minv)
    block[1, 1] = _block_product(ht[i], index, i, ht[j], j, minv)


@jit
def _contacts_by_body(na, active, index, n_bodies):
    """(start, members): the active contacts (positions in `active`) touching each body, CSR."""
    start = np.zeros(n_bodies + 1, dtype=np.int64)
    for a in range(na):
        for side in range(2):
            body = index[active[a], CI_BODY_A + side]
            if body >= 0:
                start[body + 1] += 1
    for b in range(n_bodies):
        start[b + 1] += start[b]
    members = np.empty(start[n_bodies], dtype=np.int64)
    fill = start.copy()
    for a in range(na):
        for side in range(2):
            body = index[active[a], CI_BODY_A + side]
            if body >= 0:
                members[fill[body]] = a
                fill[body] += 1
    return start, members


@jit
def delassus_blocks(na, model, work):
    """The block-sparse Delassus matrix over the active contacts (solvers.kernels' CSR layout:
    indptr, indices, 2×2 blocks): a block for each pair of contacts sharing a body, so building
    it costs O(active contacts × contacts per body), not O(contacts²)."""
    minv, index = model[0], model[3]
    hn, ht, active = work[2], work[3], work[4]
    start, members = _contacts_by_body(na, active, index, minv.shape[0] // 3)
    indptr = np.zeros(na + 1, dtype=np.int64)
    seen = np.full(na, -1, dtype=np.int64)
    for sweep in range(2):  # count, then fill
        if sweep == 1:
            indices = np.empty(indptr[na], dtype=np.int64)
            blocks = np.empty((indptr[na], 2, 2))
            seen[:] = -1
        for a in range(na):
            n = 0
            for side in range(2):
                body = index[active[a], CI_BODY_A + side]
                for m in range(start[body] if body >= 0 else 0, start[body + 1] if body >= 0 else 0):
                    b = members[m]
                    if seen[b] != a:
                        seen[b] = a
                        if sweep == 1:
                            indices[indptr[a] + n] = b
                            _fill_block(blocks[indptr[a] + n], hn, ht, index, active[a], active[b], minv)
                        n += 1
            if sweep == 0:
                indptr[a + 1] = indptr[a] + n
    return indptr, indices, blocks


@_inlined
def assemble(params, na, qk, vk, model, work, W, q_step, guess, mu_s, mu_d, closing, resting):
    """The step problem u = W p + q_step over the active contacts, with slip guesses and μs, μd;
    `resting` is 1 for a contact loaded in the previous step or not slipping at the step's start."""
    minv, table, index = model[0], model[2], model[3]
    gaps, hn, ht, active, was_closed, slip_sign, v_free = work[0], work[2], work[3], work[4], work[5], work[7], work[8]
    grazing = work[6]
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
    block = np.empty((2, 2))  # C-contiguous like delassus_blocks' blocks: _fill_block compiles once
    for a in range(na):
        i = active[a]
        for b in range(na if W.shape[0] > 0 else 0):  # dense W: for lemke and enum
            j = active[b]
            _fill_block(block, hn, ht, index, i, j, minv)
            W[2 * a: 2 * a + 2, 2 * b: 2 * b + 2] = block
        surface = table[i, C_SURFACE_VELOCITY]
        q_step[2 * a + 1] = local_dot(ht[i], index, i, v_free) - surface
        # only a contact at rest — loaded in the previous step, or not slipping at the step's start —
        # is held by a search over admissible splits (sticking.py); one grazing a rolling
        # neighbour without load keeps the solver's answer (the search costs milliseconds there)
        loaded = was_closed[i] and not grazing[i]
        resting[a] = 1.0 if loaded or abs(local_dot(ht[i], index, i, vk) - surface) <= rest_tol else 0.0
        mu_s[a], mu_d[a] = table[i, C_MU_S], table[i, C_MU_D]
        if was_closed[i]:
            # A persistent contact may close an open gap, not only keep u_N ≥ 0: the Jacobian
            # turns with the body within the step, so a purely velocity-level law lets the gap
            # creep open by O(h) per unit time. u_N ≥ −g/h for g > 0 removes the creep; a
            # penetration (g < 0) is not pushed out, which would inject energy after impacts.
            closing[a] = (gaps[i] if gaps[i] > gap_roundoff else 0.0) / h  # the part asking to close a gap
            q_step[2 * a] = local_dot(hn[i], index, i, v_free) + closing[a]
            guess[a] = slip_sign[i]
        else:
            closing[a] = 0.0
            u_n = local_dot(hn[i], index, i, vk)
            q_step[2 * a] = local_dot(hn[i], index, i, v_free) + table[i, C_RESTITUTION] * min(u_n, 0.0)
            u_t = local_dot(ht[i], index, i, vk) - surface  # a closing contact slides the way it arrives
            guess[a] = 0.0 if abs(u_t) < 1e-12 else math.copysign(1.0, u_t)
    if model[M_JOINTS].shape[0] > 0:
        _joints_delassus(na, active, hn, ht, index, minv, model[M_JOINTS], work[WORK_JOINTS], W)


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


@jit
def _record_impact(k, t, i, u_before, work, model, out, params, iparams):
    gaps, drifts, hn, a_free = work[0], work[1], work[2], work[9]
    index = model[3]
    impact_t, impact_step, impact_contact, counters = out[6], out[7], out[8], out[9]
    h = params[P_H]
    n = counters[K_N_IMPACTS]
    if n >= impact_t.shape[0]:  # the record is full: the impact still acts, unrecorded
        return i == iparams[I_STOP]
    impact_t[n] = t + crossing_offset(gaps[i], u_before, local_dot(hn[i], index, i, a_free) + drifts[i], h)
    impact_step[n] = k
    impact_contact[n] = i
    counters[K_N_IMPACTS] = n + 1
    return i == iparams[I_STOP]


@_inlined
def finish_step(k, params, iparams, na, p, u, states, qk, vk, model, work, out):
    """End-of-step state, the step's records, impacts and the contacts' memory; returns a run
    status (RUN_OK, RUN_STOPPED at the stop contact's first impact, RUN_NONFINITE)."""
    minv, table, index = model[0], model[2], model[3]
    hn, ht, active, was_closed, grazing, slip_sign, v_free = work[2], work[3], work[4], work[5], work[6], work[7], work[8]
    q, v, p_normal, p_tangent, slip, state_rec = out[0], out[1], out[2], out[3], out[4], out[5]
    h, theta = params[P_H], params[P_THETA]
    t = step_time(params, k)
    v_next = v[k + 1]
    v_next[:] = v_free
    for a in range(na):
        i = active[a]
        for side in range(2):
            body = index[i, CI_BODY_A + side]
            if body >= 0:
                for d in range(3):
                    v_next[3 * body + d] += minv[3 * body + d] * (hn[i, 3 * side + d] * p[2 * a]
                                                                  + ht[i, 3 * side + d] * p[2 * a + 1])
    joints = model[M_JOINTS].shape[0] > 0
    if joints:
        _joints_finish(v_next, minv, model[M_JOINTS], work[WORK_JOINTS], out[O_JOINT_IMPULSE][k])
    finite = True
    for d in range(qk.shape[0]):
        q[k + 1, d] = qk[d] + h * ((1.0 - theta) * vk[d] + theta * v_next[d])
        finite = finite and math.isfinite(q[k + 1, d]) and math.isfinite(v_next[d])
    if joints and finite:
        _joints_project(q[k + 1], na, states, active, hn, ht, index, minv, model[M_JOINTS], work[WORK_JOINTS])
    status = RUN_OK
    for i in range(table.shape[0]):
        p_normal[k, i] = 0.0
        p_tangent[k, i] = 0.0
        state_rec[k, i] = 0
        slip[k, i] = local_dot(ht[i], index, i, v_next) - table[i, C_SURFACE_VELOCITY]
    for i in range(table.shape[0]):
        grazing[i] = 0
    for a in range(na):
        i = active[a]
        p_normal[k, i], p_tangent[k, i], state_rec[k, i] = p[2 * a], p[2 * a + 1], states[a]
        if states[a] == STATE_OPEN and was_closed[i] and _rides_the_gap(i, params, work, index, v_next):
            grazing[i] = 1  # no force this step (reported open), yet not apart: no impact on return
        slip_sign[i] = 1.0 if state_rec[k, i] == STATE_SLIP_PLUS else (-1.0 if state_rec[k, i] == STATE_SLIP_MINUS
                                                                        else 0.0)
    for i in range(table.shape[0]):
        closed = p_normal[k, i] > 0.0
        if closed and not was_closed[i]:
            # An impact: a contact that was apart closes with approaching velocity. A persistent
            # contact that rode its gap without impulse for a step stays closed (grazing), so it
            # is not one.
            u_before = local_dot(hn[i], index, i, vk)
            if u_before < -IMPACT_VELOCITY_TOL and _record_impact(k, t, i, u_before, work, model, out, params,
                                                                  iparams):
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
def _joints_project(q_next, na, states, active, hn, ht, index, minv, table, buffer):
    """q_{k+1} projected back onto the joints' positions C(q) = 0 (their drift stays round-off),
    the contacts that held this step kept where they are."""
    _, slot, J, C, _, _, _ = _joint_state(minv, table, buffer)
    held, held_bodies = np.empty((2 * na, 6)), np.empty((2 * na, 2), dtype=np.int64)
    n_held = held_contact_rows(na, active, states, hn, ht, index, slot, held, held_bodies)
    project_positions(q_next, minv, table, J, C, held, held_bodies, n_held)


@jit
def _rides_the_gap(i, params, work, index, v_next):
    """A persistent contact that got no impulse but ends the step within h² |g̈| of
    its obstacle: it carries no force (reported open) but has not come apart, so its next loaded
    step is no impact — near a lift-off the normal force fades and such steps alternate with
    loaded ones."""
    gaps, drifts, hn, a_free = work[0], work[1], work[2], work[9]
    h = params[P_H]
    # within one step's worth of its acceleration, h² |g̈|: a hop of a ball at rest is longer
    margin = h * h * (abs(drifts[i]) + abs(local_dot(hn[i], index, i, a_free))) + ACTIVATION_ROUNDOFF
    return gaps[i] + h * local_dot(hn[i], index, i, v_next) <= margin


@_inlined
def _warm_start(k, na, work, out, p):
    """The previous step's impulses of the contacts that stay closed (pgs starts from p)."""
    active, was_closed, p_normal, p_tangent = work[4], work[5], out[2], out[3]
    if k == 0:
        return
    for a in range(na):
        i = active[a]
        if was_closed[i]:
            p[2 * a], p[2 * a + 1] = p_normal[k - 1, i], p_tangent[k - 1, i]


@_inlined
def solve_step(solver_code, k, params, iparams, na, qk, vk, model, work, out):
    """assemble + the two-coefficient kernel. Returns (kernel status, p, u, states, consistent)."""
    m = 2 * na
    # pgs sweeps the block-sparse W; lemke, enum need it dense, and so do joints (W_c couples a cluster)
    sparse = solver_code == SOLVER_PGS and model[M_JOINTS].shape[0] == 0
    W = np.zeros((0, 0)) if sparse else np.zeros((m, m))
    q_step = np.empty(m)
    guess, mu_s, mu_d, closing, resting = np.empty(na), np.empty(na), np.empty(na), np.empty(na), np.empty(na)
    assemble(params, na, qk, vk, model, work, W, q_step, guess, mu_s, mu_d, closing, resting)
    if sparse:
        indptr, indices, blocks = delassus_blocks(na, model, work)
    else:
        indptr, indices, blocks = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros((0, 2, 2))
    p, u = np.zeros(m), np.zeros(m)
    _warm_start(k, na, work, out, p)
    states = np.zeros(na, dtype=np.int64)
    if sparse:
        status, solves, iterations, consistent, fallbacks = two_coefficient_kernel(
            solver_code, W, indptr, indices, blocks, q_step, mu_s, mu_d, guess, closing, resting, params[P_RTOL],
            iparams[I_MAX_ITER], p, u, states)
    else:  # lemke, enum: one group of coupled contacts at a time (their cost grows with the group)
        status, solves, iterations, consistent, fallbacks = two_coefficient_by_group(
            solver_code, W, q_step, mu_s, mu_d, guess, closing, resting, params[P_RTOL], iparams[I_MAX_ITER], p, u,
            states)
    counters = out[9]
    counters[K_SOLVES] += solves
    counters[K_ITERATIONS] += iterations
    counters[K_FALLBACKS] += fallbacks
    if status == KERNEL_SOLVED and not consistent:
        counters[K_INCONSISTENT] += 1
    return status, p, u, states


@_inlined
def _step(solver_code, k, f, params, iparams, model, work, out):
    """One whole step with generalised force f; returns a run status (the solver read from its
    code at run time: run_steps and compiled_step serve every solver)."""
    q, v, counters = out[0], out[1], out[9]
    qk, vk = q[k], v[k]
    na = begin_step(params, qk, vk, f, model, work)
    if na < 0:
        counters[K_FAIL_CONTACT] = -1 - na
        return RUN_BAD_GEOMETRY
    p, u, states = np.zeros(0), np.zeros(0), np.zeros(0, dtype=np.int64)
    if na > 0:
        status, p, u, states = solve_step(solver_code, k, params, iparams, na, qk, vk, model, work, out)
        if status != KERNEL_SOLVED:
            counters[K_SOLVER_STATUS] = status
            return RUN_SOLVER_FAILED
    return finish_step(k, params, iparams, na, p, u, states, qk, vk, model, work, out)


@_inlined
def step_time(params, k):
    """t_k = t0 + (k0 + k) h: the start of row k's step, from the run's one origin."""
    return params[P_T0] + (params[P_K0] + k) * params[P_H]


@_inlined
def step_force(k, params, model, out, f):
    """f = weight + the packed forces at t_k + θh and (q_k, v_k)."""
    weight, ftable = model[1], model[4]
    q, v = out[0], out[1]
    f[:] = weight
    t = params[P_T0] + ((params[P_K0] + k) + params[P_THETA]) * params[P_H]
    if ftable.shape[0] > 0:
        accumulate_forces(t, q[k], v[k], ftable, model[5], model[6], model[7], f)


@_inlined
def end_of_step(k, status, counters):
    """Book step k's outcome in the counters (steps done; how and where the run ended)."""
    if status == RUN_OK or status == RUN_STOPPED:
        counters[K_DONE] = k + 1
    if status != RUN_OK:
        counters[K_STATUS] = status
        counters[K_FAIL_STEP] = k
    return status


@jit
def _run(solver_code, k_start, k_end, params, iparams, model, work, out):
    """Steps k_start … k_end − 1 with the packed forces: the whole run in one call."""
    f = np.empty(model[0].shape[0])
    for k in range(k_start, k_end):
        step_force(k, params, model, out, f)
        if end_of_step(k, _step(solver_code, k, f, params, iparams, model, work, out), out[9]) != RUN_OK:
            return out[9][K_STATUS]
    return RUN_OK


# One compiled entry for every solver, which reads its code from iparams at run time: the three
# solvers then compile together into one loop (a one-way switch per step costs nothing measurable:
# rod, h = 1e-4, 12.67 / 12.34 / 50.46 µs per step against 12.48 / 12.35 / 49.24 with one literal
# entry per solver, back to back on a loaded machine), where one entry per solver compiled the
# whole tree once per solver — a test suite or `nonsmooth-rod compile` compiled it six times.
@jit
def run_steps(k_start, k_end, params, iparams, model, work, out):
    """_run with the solver iparams[I_SOLVER] names."""
    return _run(iparams[I_SOLVER], k_start, k_end, params, iparams, model, work, out)


# The same for the step-wise loop (a Python applied_force called back between steps).
@jit
def compiled_step(k, f, params, iparams, model, work, out):
    """One step (_step) with the solver iparams[I_SOLVER] names."""
    return _step(iparams[I_SOLVER], k, f, params, iparams, model, work, out)


__all__ = ["begin_step", "assemble", "solve_step", "finish_step", "step_force", "run_steps", "compiled_step",
           "crossing_offset", "ACTIVATION_ROUNDOFF"]

