"""Acceleration-level contact dynamics of a scene for a given assignment of contact modes.

For each contact in a mode, Siconos-style: a closed contact keeps g̈ = H_N a + Ḣ_N v = 0 with
N ≥ 0; a sticking contact also keeps the slip acceleration H_T a + Ḣ_T v = 0 with |T| ≤ μs N;
a sliding contact carries T = −s μd N (s = sign of the slip velocity). The unknowns
(a, N, T) follow from one linear system (the mass matrix is constant and diagonal):

    a = M⁻¹ (f + Σ H_Nᵀ N + H_Tᵀ T),     A λ = −(Ḣ v + C M⁻¹ f),   A = C M⁻¹ G.

A sliding mode whose A loses positivity is the Painlevé situation: no or several solutions.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._jit import jit, jit_inline
from ..solvers.kernel_base import lu_factor, lu_solve
from .contact_kernels import (C_LINE_PX, C_LINE_PY, C_MU_D, C_MU_S, C_NX, C_NY, C_OBSTACLE_VX, C_OBSTACLE_VY,
                              C_SURFACE_VELOCITY, KIND_DISK_ON_LINE, N_CONTACT_COLUMNS, _on_fixed_normal,
                              obstacle_velocity)
from .contacts import ContactKinematics
from .scene import Scene

SLIP_SIGN = {"slip+": 1.0, "slip-": -1.0}


@dataclass
class ModeDynamics:
    a: np.ndarray
    normal_force: np.ndarray  # per contact (0 when open)
    tangential_force: np.ndarray
    matrix: np.ndarray  # A of the constrained system (may be empty)
    singular: bool


def mode_dynamics(scene: Scene, t: float, q: np.ndarray, v: np.ndarray,
                  modes, kin: list[ContactKinematics] | None = None) -> ModeDynamics:
    """Accelerations and contact forces with each contact in the given mode."""
    kin = kin if kin is not None else scene.kinematics(q, v)
    minv = scene.inverse_mass_diagonal
    f = scene.force(t, q, v)
    rows, cols, rhs, owners = [], [], [], []
    for i, (k, mode) in enumerate(zip(kin, modes)):
        if mode == "open":
            continue
        mu_d = scene.contacts[i].law.friction.mu_d
        rows.append(k.H_N)
        rhs.append(k.drift_N)
        if mode == "stick":
            cols.append(k.H_N)
            cols.append(k.H_T)
            rows.append(k.H_T)
            rhs.append(k.drift_T)
            owners.append((i, "N"))
            owners.append((i, "T"))
        else:
            cols.append(k.H_N - SLIP_SIGN[mode] * mu_d * k.H_T)
            owners.append((i, "N+slip"))
    nc = len(kin)
    normal = np.zeros(nc)
    tangential = np.zeros(nc)
    free_acc = minv * f
    if not rows:
        return ModeDynamics(free_acc, normal, tangential, np.zeros((0, 0)), False)
    C = np.array(rows)
    G = np.array(cols).T
    A = C @ (minv[:, None] * G)
    b = -(np.array(rhs) + C @ free_acc)
    singular = False
    try:
        if abs(np.linalg.det(A)) < 1e-12 * max(1.0, np.abs(A).max()) ** len(A):
            raise np.linalg.LinAlgError
        lam = np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        # Redundant constraints (e.g. two sticking contacts of one body at rest): forces are
        # statically indeterminate and any split gives the same (unique) motion. The
        # least-norm split can put one contact outside its friction cone although another
        # split holds; we take the split deepest inside all cones (_most_admissible_split).
        singular = True
        lam = np.linalg.lstsq(A, b, rcond=None)[0]
        lam = _most_admissible_split(A, lam, owners, modes, scene)
    for (i, role), value in zip(owners, lam):
        if role == "N":
            normal[i] = value
        elif role == "T":
            tangential[i] = value
        else:
            normal[i] = value
            tangential[i] = -SLIP_SIGN[modes[i]] * scene.contacts[i].law.friction.mu_d * value
    a = free_acc + minv * (G @ lam)
    return ModeDynamics(a, normal, tangential, A, singular)


def _most_admissible_split(A, lam0, owners, modes, scene):
    """Among the statically indeterminate forces λ0 + Z z (Z = null space of A), the split that
    maximises the smallest margin min(N_i, μs N_i − |T_i|) over the closed contacts.

    This is the question the event-driven stick test asks ("can μs hold it?"): it answers yes
    exactly when some split lies inside every cone, whatever the least-norm split says.
    """
    from scipy.linalg import null_space
    from scipy.optimize import linprog

    Z = null_space(A)
    if Z.shape[1] == 0:
        return lam0
    k = Z.shape[1]
    index = {}
    for j, (i, role) in enumerate(owners):
        index.setdefault(i, {})[role] = j
    rows, rhs = [], []

    def add(coef_lam, const=0.0):
        # margin = coef·λ + const ≥ t  ⇔  −coef·Z z + t ≤ coef·λ0 + const
        rows.append(np.r_[-(coef_lam @ Z), 1.0])
        rhs.append(float(coef_lam @ lam0) + const)

    n = len(lam0)
    for i, roles in index.items():
        e_n = np.zeros(n)
        j_n = roles.get("N", roles.get("N+slip"))
        e_n[j_n] = 1.0
        add(e_n)
        if "T" in roles:
            mu = scene.contacts[i].law.friction.mu_s
            e_t = np.zeros(n)
            e_t[roles["T"]] = 1.0
            add(mu * e_n - e_t)
            add(mu * e_n + e_t)
    # Solved in units of the forces: HiGHS's tolerances are absolute (1e-7), and at forces that
    # small (a contact about to lift off) it would return a split on the cone's edge as optimal.
    scale = float(np.max(np.abs(lam0))) or 1.0
    res = linprog(np.r_[np.zeros(k), -1.0], A_ub=np.array(rows), b_ub=np.array(rhs) / scale,
                  bounds=[(-1e3, 1e3)] * k + [(None, 1.0)], method="highs")
    if res.status != 0:
        return lam0
    return lam0 + Z @ (scale * res.x[:k])


# A contact's mode as the compiled mode solve reads it.
MODE_CODES = {"open": 0, "stick": 1, "slip+": 2, "slip-": 3}
# The rows of A a contact in each mode adds (its normal; a sticking one's tangent too), and a
# planar body's freedoms (x, y, θ: Scene.n_dof).
MODE_ROWS = {"open": 0, "stick": 2, "slip+": 1, "slip-": 1}
DOF_PER_BODY = 3
# What a mode's switches watch (ModeSystem's `watched`): a contact's gap, slip velocity, N,
# T − μs N, T + μs N; det A.
WATCH_CODES = {"gap": 0, "slip": 1, "normal": 2, "upper": 3, "lower": 4, "det": 5}


class ModeSystem:
    """`mode_dynamics` for one assignment of modes, set up once and evaluated at many states: the
    same equations, compiled (`mode_rates_into`), with the values its switches watch. A
    fixed-step integrator solves its mode thousands of times: mode_dynamics spends ~20 µs a call
    on numpy's small-array overhead, this ~3 µs on a rod's two contacts.

    For a body's disks and points on fixed lines (the contacts the hybrid method runs) whose
    constrained system is regular; `evaluate` returns None elsewhere — a statically indeterminate
    A (two sticking corners of a block at rest), whose split mode_dynamics chooses — and the caller
    falls back on mode_dynamics. `usable`: False where that is known from the modes alone (other
    contacts; a body held by more rows than its freedoms, `indeterminate_everywhere`).
    `watched`: (what, contact, offset) triples, `what` a key of WATCH_CODES; each value is the
    quantity minus the offset."""

    # None: the compiled mode solve and step; or their plain-Python twins (mode_rates_into's,
    # runge_kutta_into's: solvers._common.interpreted), set by a caller whose run goes on
    # interpreted while the engine compiles (a prediction then compiles nothing: hybrid.py)
    twins = None

    def __init__(self, scene: Scene, modes, watched=(), like: ModeSystem | None = None):
        n, nc = scene.n_dof, len(scene.contacts)
        self.scene, self.n_dof = scene, n
        if like is None:  # the scene's packed contacts; `like`: another mode's system of this scene has them
            packed = [c._packed_row() for c in scene.contacts]
            self.contacts_usable = all(kind == KIND_DISK_ON_LINE and c.obstacle_motion is None
                                       for (kind, _, _, _), c in zip(packed, scene.contacts))
            self.table = np.array([row for _, _, _, row in packed], dtype=float).reshape(nc, N_CONTACT_COLUMNS)
            self.table[:, C_MU_S] = [c.law.friction.mu_s for c in scene.contacts]
            self.table[:, C_MU_D] = [c.law.friction.mu_d for c in scene.contacts]
            self.bodies = [body for _, body, _, _ in packed]
        else:
            self.contacts_usable, self.table, self.bodies = like.contacts_usable, like.table, like.bodies
        # (a mode whose A is singular at every state is declined before any compiled call: a
        # prediction of a statically indeterminate stick costs a dict lookup, not a mode solve)
        self.usable = self.contacts_usable and not indeterminate_everywhere(self.bodies, modes)
        self.ints = np.array([(body, MODE_CODES[mode]) for body, mode in zip(self.bodies, modes)],
                             dtype=np.int64).reshape(nc, 2)
        self.watched = np.array([(WATCH_CODES[what], i) for what, i, _ in watched], dtype=np.int64).reshape(-1, 2)
        self.offsets = np.array([offset for _, _, offset in watched], dtype=float)
        self.minv = scene.inverse_mass_diagonal
        self.free = scene.inverse_mass_diagonal * scene.weight
        self.constant = not scene.forces and scene.applied_force is None
        m, k = sum(MODE_ROWS[mode] for mode in modes), len(watched)
        # out's layout: ẏ = (v, a), the watched values, N, T, det A, A's rows
        self.rates, self.accelerations, self.values = slice(0, 2 * n), slice(n, 2 * n), slice(2 * n, 2 * n + k)
        self.normal, self.tangential = slice(2 * n + k, 2 * n + k + nc), slice(2 * n + k + nc, 2 * n + k + 2 * nc)
        self.det, self.matrix = 2 * n + k + 2 * nc, slice(2 * n + k + 2 * nc + 1, None)
        self.m, self.out = m, np.empty(2 * n + k + 2 * nc + 1 + m * m)

    def evaluate(self, t: float, y: np.ndarray) -> np.ndarray | None:
        """A new array in the layout above at (t, y = (q, v)), or None where mode_dynamics must
        decide (see the class)."""
        if not self.usable:
            return None
        free = self.free
        if not self.constant:
            n = self.n_dof
            free = self.minv * self.scene.force(t, y[:n], y[n:])
        rates_into = mode_rates_into if self.twins is None else self.twins[0]
        if not rates_into(self.table, self.ints, self.watched, self.offsets, self.minv, free, y, self.out):
            return None
        return self.out.copy()

    def runge_kutta(self, y: np.ndarray, h: float, a: np.ndarray, b: np.ndarray):
        """One explicit Runge–Kutta step of h from y (the tableau's a, lower triangular, and b) in
        one compiled call: (the stages' states and the end state, rows of an (s + 1) × 2n array;
        their evaluations in the layout above, rows alike), or None where `evaluate` would decline
        or the forces are not constant (the caller steps stage by stage). The stages' sums are
        those of y + h Σ a_ij f_j over the nonzero weights, in order, as the caller's."""
        if not (self.usable and self.constant):
            return None
        s = b.shape[0]
        states, outs = np.empty((s + 1, y.shape[0])), np.empty((s + 1, self.out.shape[0]))
        step_into = runge_kutta_into if self.twins is None else self.twins[1]
        if not step_into(self.table, self.ints, self.watched, self.offsets, self.minv, self.free, y, h, a, b,
                         states, outs):
            return None
        return states, outs

    def dynamics(self, out: np.ndarray) -> ModeDynamics:
        """The ModeDynamics of an evaluation."""
        return ModeDynamics(out[self.accelerations], out[self.normal], out[self.tangential],
                            out[self.matrix].reshape(self.m, self.m), False)


def indeterminate_everywhere(bodies, modes) -> bool:
    """Whether A is singular at every state: some body held by more rows (a closed contact's
    normal, a sticking one's tangent too) than its 3 freedoms. A = C M⁻¹ Gᵀ, C's rows a body's
    are functions of its 3 velocities: A's rank is at most 3 a body (its contacts are with fixed
    lines: A has no entry between bodies), less than its rows — two sticking disks of a block."""
    rows: dict = {}
    for body, mode in zip(bodies, modes):
        rows[body] = rows.get(body, 0) + MODE_ROWS[mode]
    return any(m > DOF_PER_BODY for m in rows.values())


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def mode_rates_into(table, ints, watched, offsets, minv, free, y, out) -> bool:
    """The mode solve of mode_dynamics for disks on fixed lines and its watched values
    (`ModeSystem`, out in its layout); False where A is singular (the threshold of
    mode_dynamics), out then incomplete."""
    n, nc = minv.shape[0], ints.shape[0]
    q, v = y[:n], y[n:]
    m = 0
    for i in range(nc):
        m += 0 if ints[i, 1] == 0 else (2 if ints[i, 1] == 1 else 1)
    C, G = np.zeros((m, 3)), np.zeros((m, 3))
    base, owner, role = np.zeros(m, np.int64), np.zeros(m, np.int64), np.zeros(m, np.int64)
    M = np.zeros((m, m + 1))
    hn, ht, gaps, slips = np.zeros(6), np.zeros(6), np.zeros(nc), np.zeros(nc)
    r = 0
    for i in range(nc):
        row, body, mode = table[i], ints[i, 0], ints[i, 1]
        gap, drift_n, drift_t = _on_fixed_normal(row, body, q, v, hn, ht, row[C_NX], row[C_NY], row[C_LINE_PX],
                                                 row[C_LINE_PY])
        w_t = obstacle_velocity(hn[0], hn[1], ht[0], ht[1], row[C_OBSTACLE_VX], row[C_OBSTACLE_VY],
                                row[C_SURFACE_VELOCITY])[1]
        j = 3 * body
        gaps[i], slips[i] = gap, ht[0] * v[j] + ht[1] * v[j + 1] + ht[2] * v[j + 2] - w_t
        if mode == 0:
            continue
        s = 0.0 if mode == 1 else (1.0 if mode == 2 else -1.0) * row[C_MU_D]
        for d in range(3):
            C[r, d], G[r, d] = hn[d], hn[d] - s * ht[d]
        base[r], owner[r], role[r], M[r, m] = j, i, 0 if mode == 1 else 2, drift_n
        r += 1
        if mode == 1:
            for d in range(3):
                C[r, d], G[r, d] = ht[d], ht[d]
            base[r], owner[r], role[r], M[r, m] = j, i, 1, drift_t
            r += 1
    if not _solve_mode(C, G, base, owner, role, M, minv, free, table, ints, out[n:], watched.shape[0]):
        return False
    for d in range(n):
        out[d] = v[d]
    _watched_values(watched, offsets, table, gaps, slips, out, 2 * n, nc)
    return True


@jit
def runge_kutta_into(table, ints, watched, offsets, minv, free, y, h, a, b, states, outs) -> bool:
    """ModeSystem.runge_kutta: states[i] the stage i's state (states[s] the end), outs[i] its
    mode_rates_into; False where a mode solve declines."""
    s, dim = b.shape[0], y.shape[0]
    for i in range(s + 1):
        weights = b if i == s else a[i]
        for d in range(dim):
            total, started = 0.0, False
            for j in range(min(i, s)):
                if weights[j] != 0.0:
                    term = weights[j] * outs[j, d]
                    total = term if not started else total + term
                    started = True
            states[i, d] = y[d] + h * total if started else y[d]
        if not mode_rates_into(table, ints, watched, offsets, minv, free, states[i], outs[i]):
            return False
    return True


@jit
def hermite_into(weights, h, y0, y1, f0, f1, out):
    """A cubic Hermite interpolant of a step of h from both ends' states y and rates f into out:
    with weights (h00, h01, h10, h11), numpy's h00 y0 + h01 y1 + h (h10 f0 + h11 f1) element by
    element — the same numbers without seven small arrays (the weights come from the caller:
    numba's power of a float can differ from Python's in the last bit)."""
    h00, h01, h10, h11 = weights
    for d in range(out.shape[0]):
        out[d] = h00 * y0[d] + h01 * y1[d] + h * (h10 * f0[d] + h11 * f1[d])


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _watched_values(watched, offsets, table, gaps, slips, out, at, nc):
    """The watched values (WATCH_CODES) into out[at:], from the gaps, slips and out's N, T, det."""
    k = watched.shape[0]
    normal, tangential, det = at + k, at + k + nc, out[at + k + 2 * nc]
    for w in range(k):
        code, i = watched[w, 0], watched[w, 1]
        mu_n = table[i, C_MU_S] * out[normal + i]
        value = det
        if code == 0:
            value = gaps[i]
        elif code == 1:
            value = slips[i]
        elif code == 2:
            value = out[normal + i]
        elif code == 3:
            value = out[tangential + i] - mu_n
        elif code == 4:
            value = out[tangential + i] + mu_n
        out[at + w] = value - offsets[w]


@jit
def _solve_mode(C, G, base, owner, role, M, minv, free, table, ints, out, k) -> bool:
    """A λ = −(Ḣ v + C M⁻¹ f) with A = C M⁻¹ Gᵀ, then out = (a, k values left, N, T, det A, A)
    (mode_rates_into's rows)."""
    n, nc, m = minv.shape[0], ints.shape[0], C.shape[0]
    normal, tangential, at_det = n + k, n + k + nc, n + k + 2 * nc
    scale = 1.0
    for r in range(m):
        j = base[r]
        M[r, m] = -(M[r, m] + C[r, 0] * free[j] + C[r, 1] * free[j + 1] + C[r, 2] * free[j + 2])
        for c in range(m):
            a_rc = 0.0
            if base[c] == j:
                a_rc = C[r, 0] * minv[j] * G[c, 0] + C[r, 1] * minv[j + 1] * G[c, 1] + C[r, 2] * minv[j + 2] * G[c, 2]
            M[r, c] = a_rc
            out[at_det + 1 + m * r + c] = a_rc
            scale = max(scale, abs(a_rc))
    det = _eliminate(M)
    out[at_det] = det
    if not abs(det) >= 1e-12 * scale ** m:
        return False
    for i in range(n):
        out[i] = free[i]
    for i in range(nc):
        out[normal + i] = 0.0
        out[tangential + i] = 0.0
    for r in range(m):
        lam, j, i = M[r, m], base[r], owner[r]
        for d in range(3):
            out[j + d] += minv[j + d] * G[r, d] * lam
        if role[r] == 1:
            out[tangential + i] = lam
        else:
            out[normal + i] = lam
            if role[r] == 2:
                sign = 1.0 if ints[i, 1] == 2 else -1.0
                out[tangential + i] = -sign * table[i, C_MU_D] * lam
    return True


@jit_inline  # into its one caller: a dispatcher of its own would optimise its code again there
def _eliminate(M) -> float:
    """Gaussian elimination with partial pivoting of the augmented M = [A | b], in place: the last
    column becomes x (where A is regular); returns det A (0 when a pivot is zero). The package's
    one LU (solvers.kernel_base.lu_factor, lu_solve): the same operations in the same order as
    eliminating b along with A."""
    m = M.shape[0]
    rows = np.empty(m, dtype=np.int64)
    if not lu_factor(M, m, rows, 0.0):
        return 0.0
    det = 1.0
    for k in range(m):
        if rows[k] != k:
            det = -det
        det *= M[k, k]
    lu_solve(M, m, rows, M[:, m])
    return det
