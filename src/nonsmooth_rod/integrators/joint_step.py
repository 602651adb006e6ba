"""Bilateral joints inside a Moreau–Jean step: their rows eliminated (docs/joints.md).

With the joints' Jacobian J = ∂C/∂q at q_k (model/joints.py) and A = J M⁻¹ Jᵀ, the step's end
velocity is v_{k+1} = v_free + M⁻¹Hᵀp + M⁻¹Jᵀλ with J v_{k+1} = 0, so

    λ = −A⁺ J (v_free + M⁻¹Hᵀp),   v_{k+1} = P (v_free + M⁻¹Hᵀp),   P = I − M⁻¹JᵀA⁺J,

and the contacts see u = H P v_free + H W_c Hᵀ p with the constrained inverse mass
W_c = P M⁻¹ = M⁻¹ − M⁻¹JᵀA⁺JM⁻¹: exactly the contact problem of a scene without joints, with
the free velocity projected and W_c in place of M⁻¹. W_c is dense over the dofs of the jointed
bodies only (two contacts on different bodies of one jointed cluster couple), diagonal
elsewhere. A⁺ is a pseudo-inverse (eigenvalues of A below EIGEN_CUTOFF of the largest are
dropped): redundant joints — a body pinned twice at one point — share the load, never NaN.

After the step, the positions are projected back onto C(q) = 0 by Newton's iteration in the
mass metric, Δq = −M⁻¹GᵀA⁺[C(q); 0], G = [J; the rows of the contacts that held in the step]:
the joints' drift stays at round-off however long the run, and what the contacts held stays.
Every function takes plain arrays; moreau_jean_loop unpacks its tuples into them.
"""
from __future__ import annotations

import math

import numpy as np

from .._jit import jit, jit_inline
from ..model.joints import ROWS_PER_JOINT, joint_rows, jointed_dofs
from ..model.packing import CI_BODY_A
from ..solvers.two_coefficient import STATE_OPEN, STATE_STICK

# Relative size (to A's largest eigenvalue) below which an eigenvalue of A = J M⁻¹ Jᵀ counts as
# zero: a redundant joint's rows make A singular up to round-off (~1e-16 of its scale).
EIGEN_CUTOFF = 1e-10
# Newton iterations of the position projection (quadratic: 2–3 reach round-off after a step).
MAX_PROJECTION_ITERATIONS = 8
# A joint's violation below this many ulps of the largest coordinate is round-off: done.
PROJECTION_ULPS = 4.0


@jit
def pseudo_inverse(A, A_pinv):
    """A_pinv = A⁺ of the symmetric positive semi-definite A (eigenvalues ≤ EIGEN_CUTOFF λ_max dropped)."""
    n = A.shape[0]
    A_pinv[:, :] = 0.0
    if n == 0:
        return
    values, vectors = np.linalg.eigh(A)
    top = max(values[n - 1], 0.0)
    for m in range(n):
        if values[m] > EIGEN_CUTOFF * top and values[m] > 0.0:
            inv = 1.0 / values[m]
            for r in range(n):
                for s in range(n):
                    A_pinv[r, s] += vectors[r, m] * inv * vectors[s, m]


def work_size(table, n_dof: int) -> int:
    """Floats of the joints' work buffer (joint_views) for the joint table and n_dof."""
    if not table.shape[0]:  # no joints (most scenes): no call of the compiled jointed_dofs
        return 0
    rows, nd = ROWS_PER_JOINT * table.shape[0], jointed_dofs(table, n_dof)[0].shape[0]
    return rows * n_dof + rows + rows * rows + nd * nd + rows


@jit
def joint_views(buffer, rows, n_dof, nd):
    """(J, C, A⁺, W_c, λ_free) as views of the one work buffer (work_size floats)."""
    a = rows * n_dof
    b = a + rows
    c = b + rows * rows
    d = c + nd * nd
    return (buffer[:a].reshape((rows, n_dof)), buffer[a:b], buffer[b:c].reshape((rows, rows)),
            buffer[c:d].reshape((nd, nd)), buffer[d:d + rows])


@jit
def joint_operators(q, minv, table, dofs, J, C, A_pinv, WC):
    """J and C at q, A⁺ = (J M⁻¹ Jᵀ)⁺ and, when WC is given (non-empty), W_c over the jointed dofs."""
    joint_rows(table, q, J, C)
    nr, nd = J.shape[0], dofs.shape[0]
    A = np.zeros((nr, nr))
    for r in range(nr):
        for s in range(r, nr):
            x = 0.0
            for a in range(nd):
                d = dofs[a]
                x += J[r, d] * minv[d] * J[s, d]
            A[r, s] = x
            A[s, r] = x
    pseudo_inverse(A, A_pinv)
    if WC.shape[0] == 0:
        return
    B = np.empty((nd, nr))  # M⁻¹Jᵀ over the jointed dofs
    for a in range(nd):
        for r in range(nr):
            B[a, r] = minv[dofs[a]] * J[r, dofs[a]]
    BA = B @ A_pinv
    for a in range(nd):
        for b in range(a, nd):
            x = 0.0
            for r in range(nr):
                x += BA[a, r] * B[b, r]
            w = (minv[dofs[a]] if a == b else 0.0) - x
            WC[a, b] = w
            WC[b, a] = w


@jit
def project_onto_joints(x, minv, J, A_pinv, lam):
    """x ← P x = x + M⁻¹Jᵀλ with λ = −A⁺ J x (returned in lam): the velocity closest to x in the
    mass metric that the joints allow."""
    nr = J.shape[0]
    Jx = J @ x
    for r in range(nr):
        s = 0.0
        for c in range(nr):
            s -= A_pinv[r, c] * Jx[c]
        lam[r] = s
    for d in range(x.shape[0]):
        s = 0.0
        for r in range(nr):
            s += J[r, d] * lam[r]
        x[d] += minv[d] * s


@jit
def _constrained_product(row_i, index, i, row_j, j, minv, slot, WC):
    """row_i W_c row_jᵀ for two contacts' 6-entry rows (W_c: M⁻¹ off the jointed dofs)."""
    s = 0.0
    for side_i in range(2):
        body_i = index[i, CI_BODY_A + side_i]
        if body_i < 0:
            continue
        for side_j in range(2):
            body_j = index[j, CI_BODY_A + side_j]
            if body_j < 0:
                continue
            for d in range(3):
                di = 3 * body_i + d
                for e in range(3):
                    dj = 3 * body_j + e
                    if slot[di] >= 0 and slot[dj] >= 0:
                        w = WC[slot[di], slot[dj]]
                    elif di == dj:
                        w = minv[di]
                    else:
                        continue
                    s += row_i[3 * side_i + d] * w * row_j[3 * side_j + e]
    return s


@jit
def constrained_delassus(na, active, hn, ht, index, minv, slot, WC, W):
    """The dense Delassus matrix H W_c Hᵀ over the active contacts (overwrites W)."""
    for a in range(na):
        i = active[a]
        for b in range(na):
            j = active[b]
            W[2 * a, 2 * b] = _constrained_product(hn[i], index, i, hn[j], j, minv, slot, WC)
            W[2 * a, 2 * b + 1] = _constrained_product(hn[i], index, i, ht[j], j, minv, slot, WC)
            W[2 * a + 1, 2 * b] = _constrained_product(ht[i], index, i, hn[j], j, minv, slot, WC)
            W[2 * a + 1, 2 * b + 1] = _constrained_product(ht[i], index, i, ht[j], j, minv, slot, WC)


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def held_contact_rows(na, active, states, touching, hn, ht, index, slot, rows, bodies):
    """The contact rows the position projection must not move (rows, bodies filled; returns their
    count): of the contacts closed this step on a jointed body — loaded, or `touching` (active,
    unloaded, yet ending the step at their obstacle: an unloaded pair of a slider's corners on
    its guide, which the projection would otherwise push into the guide or away from it) — the
    normal row, and the tangent row of a sticking one."""
    m = 0
    for a in range(na):
        i = active[a]
        jointed = False
        for side in range(2):
            body = index[i, CI_BODY_A + side]
            jointed = jointed or (body >= 0 and slot[3 * body] >= 0)
        if (states[a] == STATE_OPEN and not touching[a]) or not jointed:
            continue
        for which in range(2 if states[a] == STATE_STICK else 1):
            rows[m, :] = hn[i] if which == 0 else ht[i]
            bodies[m, 0], bodies[m, 1] = index[i, CI_BODY_A], index[i, CI_BODY_A + 1]
            m += 1
    return m


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def _projection_system(q, table, J, C, held, held_bodies, n_held, G, target):
    """G = [J(q); the held contact rows], target = [C(q); 0]; returns max |C|."""
    joint_rows(table, q, J, C)
    nr = J.shape[0]
    G[:, :] = 0.0
    G[:nr, :] = J
    violation = 0.0
    for r in range(nr):
        target[r] = C[r]
        violation = max(violation, abs(C[r]))
    for m in range(n_held):
        target[nr + m] = 0.0
        for side in range(2):
            body = held_bodies[m, side]
            if body >= 0:
                for d in range(3):
                    G[nr + m, 3 * body + d] = held[m, 3 * side + d]
    return violation


@jit_inline  # into its one caller: a dispatcher of its own would optimise its callees' code again
def project_positions(q, minv, table, J, C, held, held_bodies, n_held):
    """Newton's iteration in the mass metric, q ← q − M⁻¹GᵀA⁺[C(q); 0] with G = [J; held contact
    rows] and A = G M⁻¹ Gᵀ: the joints' violation goes back to round-off of the coordinates (or
    stops decreasing) while the contacts that held this step keep their gap and, sticking, their
    point (a cart held by friction is not pushed along by its pendulum's correction). Returns
    the violation max |C| left."""
    n = q.shape[0]
    scale = 1.0
    for d in range(n):
        scale = max(scale, abs(q[d]))
    tol = PROJECTION_ULPS * 2.220446049250313e-16 * scale
    rows = J.shape[0] + n_held
    G, target, A, A_pinv = np.zeros((rows, n)), np.zeros(rows), np.empty((rows, rows)), np.empty((rows, rows))
    before = math.inf
    for _ in range(MAX_PROJECTION_ITERATIONS):
        violation = _projection_system(q, table, J, C, held, held_bodies, n_held, G, target)
        if violation <= tol or not violation < before:
            return violation
        before = violation
        for r in range(rows):
            for c in range(r, rows):
                x = 0.0
                for d in range(n):
                    x += G[r, d] * minv[d] * G[c, d]
                A[r, c] = x
                A[c, r] = x
        pseudo_inverse(A, A_pinv)
        lam = A_pinv @ target
        for d in range(n):
            x = 0.0
            for r in range(rows):
                x += G[r, d] * lam[r]
            q[d] -= minv[d] * x
    return before


__all__ = ["joint_operators", "project_onto_joints", "constrained_delassus", "project_positions", "held_contact_rows",
           "pseudo_inverse", "work_size", "joint_views"]
