"""One contact's step problem solved in closed form, where its solution is unique.

A group of one contact is u = W p + q with W = [[a, b_NT], [b_TN, c]] and the friction interval
p_T ∈ [lo p_N, hi p_N] (problem.PlanarFrictionProblem; lo ≤ hi). When

    a > 0,   a + b_NT lo > 0,   a + b_NT hi > 0   (the normal row stiff along both cone edges)
    det = a c − b_NT b_TN > 0                       (the stick system regular)

the solution is unique (below), so it is the one Lemke, enum and pgs find, and the step can
take it directly instead of building and pivoting Lemke's 3 × 8 tableau:

* q_N ≥ 0: open, p = 0. (A closed answer would need a p_N + b_NT p_T = −q_N ≤ 0 with
  p_T ∈ [lo p_N, hi p_N], p_N > 0; but that is ≥ p_N min(a + b_NT lo, a + b_NT hi) > 0.)
* q_N < 0: closed (p_N = 0 leaves u_N = q_N < 0). On u_N = 0, p_N = (X − b_NT p_T)/a with
  X = −q_N > 0, and u_T = (det/a) p_T + r is increasing in p_T; the interval becomes
  p_T ∈ [L, H], L = lo X/(a + b_NT lo), H = hi X/(a + b_NT hi) (p_T/p_N increases with p_T).
  The one p_T with u_T ⊥ [L, H] is the stick solution's p_T clamped to [L, H]: stick inside,
  slip at the bound otherwise (p_N = X/(a + b_NT bound), p_T = bound · p_N: exactly on the
  bound, as Lemke's interval LCP gives it).

Outside these conditions (a Painlevé configuration, a singular W, non-finite data) the caller's
solver runs as before. Equality with Lemke on random problems and on the shipped scenes:
tests/solvers/test_one_contact.py.
"""
from __future__ import annotations

import math

from .._jit import jit_borrowing, jit_inline
from .kernel_base import DEFAULT_RTOL, one_contact_residual

# Relative margins of the conditions above: closer to them the problem is left to the solver
# (its answer there may be one of several, or ill-conditioned).
STIFFNESS_MARGIN = 1e-8
SINGULAR_MARGIN = 1e-10


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def one_contact_impulse(a, b_nt, b_tn, c, q_n, q_t, lo, hi):
    """(found, p_N, p_T) of the one-contact problem above; found False when the conditions for a
    unique solution do not hold (or a datum is not finite): the caller's solver decides then."""
    if not (math.isfinite(q_n) and math.isfinite(q_t) and math.isfinite(lo) and math.isfinite(hi)):
        return False, 0.0, 0.0
    det = a * c - b_nt * b_tn
    stiff_lo, stiff_hi = a + b_nt * lo, a + b_nt * hi
    if not (a > 0.0 and c > 0.0 and lo <= hi and det > SINGULAR_MARGIN * a * c
            and stiff_lo > STIFFNESS_MARGIN * a and stiff_hi > STIFFNESS_MARGIN * a):
        return False, 0.0, 0.0
    if q_n >= 0.0:
        return True, 0.0, 0.0
    x = -q_n
    p_t = (-a * q_t - b_tn * x) / det  # the stick system [a b_NT; b_TN c] p = (X, −q_T)
    if p_t < lo * x / stiff_lo:
        p_n = x / stiff_lo
        return True, p_n, lo * p_n
    if p_t > hi * x / stiff_hi:
        p_n = x / stiff_hi
        return True, p_n, hi * p_n
    # p_N from the normal row itself, as Lemke's pivot on it gives it: u_N = 0 to the last bit where it
    # can be (a ball resting on a floor: p_N = X / a, its velocity exactly 0 after the step)
    return True, (x - b_nt * p_t) / a, p_t


@jit_borrowing
def one_contact_into(W, blocks, q, lo, hi, p, u):
    """p, u = W p + q of a one-contact problem in closed form (one_contact_impulse) — W dense
    (2 × 2) or its one block (`blocks`, the block-sparse form) — and returns the complementarity
    residual; −1 (p, u untouched) when it is not one contact, its answer may not be unique, or the
    closed form misses DEFAULT_RTOL (the caller's solver then runs)."""
    if lo.shape[0] != 1:
        return -1.0
    if W.shape[0] == 2:
        a, b_nt, b_tn, c = W[0, 0], W[0, 1], W[1, 0], W[1, 1]
    elif blocks.shape[0] == 1:
        a, b_nt, b_tn, c = blocks[0, 0, 0], blocks[0, 0, 1], blocks[0, 1, 0], blocks[0, 1, 1]
    else:
        return -1.0
    found, p_n, p_t = one_contact_impulse(a, b_nt, b_tn, c, q[0], q[1], lo[0], hi[0])
    if not found:
        return -1.0
    u_n, u_t = a * p_n + b_nt * p_t + q[0], b_tn * p_n + c * p_t + q[1]
    residual = one_contact_residual(lo[0], hi[0], p_n, p_t, u_n, u_t)
    scale = max(abs(q[0]), abs(q[1]), abs(p_n), abs(p_t), abs(u_n), abs(u_t))
    if residual > DEFAULT_RTOL * (scale if scale > 0.0 else 1.0):
        return -1.0
    p[0], p[1], u[0], u[1] = p_n, p_t, u_n, u_t
    return residual


__all__ = ["one_contact_impulse", "one_contact_into"]
