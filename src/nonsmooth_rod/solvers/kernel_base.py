"""Status codes, solver codes and the small compiled helpers every solver kernel shares.

`kernels` re-exports all of it (the interface the compiled loops use); the solver modules
import it from here, below `kernels`, to avoid an import cycle.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_borrowing, jit_inline
from .registry import BLOCK_SPARSE_CODES, SOLVER_CODES, spec  # noqa: F401 (re-exported)

# Status codes.
KERNEL_SOLVED = 0
KERNEL_RAY = 1  # Lemke: no solution by complementary pivoting
KERNEL_NO_CONVERGENCE = 2  # iteration/pivot limit, or an answer that misses the step law
KERNEL_TOO_LARGE = 3  # enum beyond its contact limit
KERNEL_NONFINITE = 4  # NaN/inf in the data

# Solver codes: the table's (registry.SOLVERS), named for the compiled dispatch.
SOLVER_LEMKE = spec("lemke").code
SOLVER_PGS = spec("pgs").code
SOLVER_ENUM = spec("enum").code
STATUS_NAMES = ("solved", "ray", "no-convergence", "too-large", "non-finite")

# Default acceptance (relative): the same for the three solvers, so that none of them fails
# where another one's answer would be accepted.
DEFAULT_RTOL = 1e-9  # = lemke.RESIDUAL_TOL and enumeration.ACCEPT_TOL


@jit
def takes_block_sparse(solver_code) -> bool:
    """True when the compiled loop hands the solver of this code the block-sparse W (the
    table's block_sparse), not the dense one; False for no compiled solver (−1)."""
    return 0 <= solver_code < len(BLOCK_SPARSE_CODES) and BLOCK_SPARSE_CODES[solver_code]


@jit_borrowing
def all_finite(values) -> bool:
    """True when no entry of the array (a vector, a matrix, a stack of blocks) is NaN or ±inf.
    Borrowing (the step's hot path screens its problem with it): `flat` walks the array where it
    lies, contiguous or not, where `ravel` would copy a non-contiguous one."""
    for x in values.flat:
        if not np.isfinite(x):
            return False
    return True


@jit_borrowing
def step_residual(W, q, lo, hi, p, u):
    """u = W p + q in place; return the complementarity residual (problem.py's formula)."""
    m = q.shape[0]
    for i in range(m):
        value = q[i]
        for j in range(m):
            value += W[i, j] * p[j]
        u[i] = value
    return contact_residual(lo, hi, p, u)


@jit_borrowing
def contact_residual(lo, hi, p, u):
    """max over contacts of one_contact_residual."""
    residual = 0.0
    for i in range(lo.shape[0]):
        residual = max(residual, one_contact_residual(lo[i], hi[i], p[2 * i], p[2 * i + 1], u[2 * i], u[2 * i + 1]))
    return residual


@jit_borrowing
def one_contact_residual(lo, hi, p_n, p_t, u_n, u_t):
    """max(|min(p_N, u_N)|, |p_T − proj_[lo p_N⁺, hi p_N⁺](p_T − u_T)|): one contact's distance from the law."""
    p_n_pos = max(p_n, 0.0)
    trial = p_t - u_t
    low = lo * p_n_pos
    high = hi * p_n_pos
    projected = low if trial < low else (high if trial > high else trial)
    return max(abs(min(p_n, u_n)), abs(p_t - projected))


@jit_borrowing
def problem_scale(q, p, u) -> float:
    """max(‖q‖∞, ‖p‖∞, ‖u‖∞), or 1 when all vanish: what a relative tolerance multiplies."""
    scale = 0.0
    for i in range(q.shape[0]):
        scale = max(scale, abs(q[i]), abs(p[i]), abs(u[i]))
    return scale if scale > 0.0 else 1.0


# ---------------------------------------------------------------- dense elimination
# The package's one dense LU (partial pivoting, in place, borrowing: it allocates nothing): Lemke's
# warm answer, the hold search's bordered trials (sticking) and the event-driven reference's mode
# equations (model.dynamics) factor and solve with it.


@jit_borrowing
def lu_factor(A, m, rows, pivot_tol):
    """A = P L U in place (L's multipliers below the diagonal, rows[c]: the row swapped into c),
    partial pivoting; False when the largest pivot left is ≤ pivot_tol: A singular to round-off."""
    for c in range(m):
        r = c
        for i in range(c + 1, m):
            if abs(A[i, c]) > abs(A[r, c]):
                r = i
        if abs(A[r, c]) <= pivot_tol:
            return False
        rows[c] = r
        if r != c:
            for j in range(m):
                A[c, j], A[r, j] = A[r, j], A[c, j]
        for i in range(c + 1, m):
            factor = A[i, c] / A[c, c]
            A[i, c] = factor
            if factor != 0.0:
                for j in range(c + 1, m):
                    A[i, j] -= factor * A[c, j]
    return True


@jit_borrowing
def lu_solve(A, m, rows, x):
    """x ← A⁻¹ x with A factored by lu_factor (its swaps moved whole rows, L's multipliers too:
    all of them apply to x first)."""
    for c in range(m):
        r = rows[c]
        if r != c:
            x[c], x[r] = x[r], x[c]
    for c in range(m):
        for i in range(c + 1, m):
            x[i] -= A[i, c] * x[c]
    for c in range(m - 1, -1, -1):
        value = x[c]
        for j in range(c + 1, m):
            value -= A[c, j] * x[j]
        x[c] = value / A[c, c]


# ---------------------------------------------------------------- per-run scratch
# A step's temporaries come from two buffers (floats, int64s) allocated once per run and carved
# from the front, each level passing what it leaves to the level below (the sign iteration, then
# Lemke): a numba allocation and its release cost ~60 ns each, and a step of the rod made ~40 of
# them. A problem larger than the buffers gets buffers of its own (solver_scratch) instead.


@jit
def solver_floats(n_contacts):
    """Floats the two-coefficient kernel and Lemke (the cone LCP, 4 unknowns per contact) take for
    a problem of n_contacts contacts (pgs on the dense W takes fewer: gauss_seidel.pgs_dense_floats)."""
    n = n_contacts
    return 52 * n * n + 64 * n + 16


@jit
def solver_ints(n_contacts):
    """int64s Lemke (8 per contact) or pgs on the dense W (its blocks' columns, n²) take."""
    n = n_contacts
    return n * n + 8 * n + 8


@jit
def solver_scratch(n_contacts):
    """(floats, int64s) for a problem of n_contacts contacts."""
    return np.empty(solver_floats(n_contacts)), np.empty(solver_ints(n_contacts), dtype=np.int64)


@jit
def fitting_scratch(floats, ints, n_contacts):
    """The scratch itself when it holds a problem of n_contacts contacts, else a new one."""
    if fits_scratch(floats, ints, n_contacts):
        return floats, ints
    return solver_scratch(n_contacts)


@jit_borrowing
def fits_scratch(floats, ints, n_contacts):
    """True when (floats, ints) hold a problem of n_contacts contacts (solver_scratch's sizes)."""
    return floats.shape[0] >= solver_floats(n_contacts) and ints.shape[0] >= solver_ints(n_contacts)


# Inlined: a view made in a borrowing caller (the step's hot path) then counts no reference.
@jit_inline
def carve(buffer, at, n):
    """(buffer[at:at + n], at + n): the next n entries of a scratch buffer."""
    return buffer[at:at + n], at + n


@jit_inline
def carve_matrix(buffer, at, rows, cols):
    """(the next rows × cols entries as a C-contiguous matrix, the offset after them)."""
    return buffer[at:at + rows * cols].reshape((rows, cols)), at + rows * cols
