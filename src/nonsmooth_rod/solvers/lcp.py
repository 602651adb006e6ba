"""Linear complementarity problems: find z with  0 ≤ z ⊥ w = M z + q ≥ 0.

    from nonsmooth_rod.solvers import lcp
    result = lcp.lemke(M, q)
    if result.success:
        z, w = result.z, result.w

`lemke` is Lemke's complementary pivoting method (covering vector (1, …, 1), lexicographic
minimum-ratio rule, so degenerate problems do not cycle), the same compiled kernel the
friction solver uses (`solvers.lemke`). It processes, i.e. solves or proves infeasible by
ending on a secondary ray, every LCP whose M is a P-matrix (then the solution is unique),
positive semi-definite, or copositive-plus; for other M a ray does not prove that no solution
exists. Failure is reported in ``status``, never raised; bad input (shapes, NaN/inf) raises
`nonsmooth_rod.validation.InputError` naming M or q.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .lemke import INACCURATE, OVERFLOW, PIVOT_LIMIT, RAY, SOLVED, TIME_LIMIT, run_lemke

STATUS = {SOLVED: "solved", RAY: "ray", PIVOT_LIMIT: "pivot-limit", TIME_LIMIT: "time-limit",
          OVERFLOW: "overflow", INACCURATE: "inaccurate"}


@dataclass(frozen=True)
class LCPResult:
    """z, w = M z + q, status "solved" | "ray" | "pivot-limit" | "time-limit" | "overflow" |
    "inaccurate", and the pivots made.

    On "ray" (no solution found by complementary pivoting: for P-matrix, positive
    semi-definite or copositive-plus M the LCP is infeasible) and "pivot-limit", z is the
    last point of the pivoting path, not a solution; on "time-limit", "overflow" (the solution
    is beyond float64's range) and "inaccurate" (w ≥ 0 or z·w = 0 violated by more than 1e-9 of
    a row's scale, both ways of scaling tried) z is not a solution either.
    """

    z: np.ndarray
    w: np.ndarray
    status: str
    pivots: int

    @property
    def success(self) -> bool:
        return self.status == "solved"


def lemke(M, q, max_pivots: int | None = None, time_limit: float | None = None) -> LCPResult:
    """Solve 0 ≤ z ⊥ M z + q ≥ 0 by Lemke's method (module docstring).

    M is n × n (n ≥ 1), q has n entries; both finite. M and q are equilibrated first (rows and
    columns scaled by powers of two), so badly scaled problems (entries 1e-200 to 1e200) solve
    as well as well-scaled ones. ``max_pivots``: pivot limit, default 50 + 20 n, at most 10¹²
    (status "pivot-limit"). ``time_limit``: wall-clock seconds, checked every ~10 ms of
    pivoting (status "time-limit"; default: none). A solution beyond float64's range (a tiny M
    with a huge q) is status "overflow", never "solved" with inf in z; "solved" means w ≥ 0 and
    z·w = 0 within 1e-9 of each row's scale |q_i| + Σ|M_ij z_j|.
    """
    z, w, status, pivots, _, _ = run_lemke(M, q, max_pivots, None, time_limit)  # validates M, q
    return LCPResult(z=z, w=w, status=STATUS[int(status)], pivots=int(pivots))


__all__ = ["lemke", "LCPResult"]
