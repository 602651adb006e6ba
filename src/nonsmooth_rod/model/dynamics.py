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
