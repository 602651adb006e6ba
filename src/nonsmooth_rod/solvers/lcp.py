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

from .lemke import PIVOT_LIMIT, RAY, run_lemke

STATUS = {0: "solved", RAY: "ray", PIVOT_LIMIT: "pivot-limit"}


@dataclass(frozen=True)
class LCPResult:
    """z, w = M z + q, status "solved" | "ray" | "pivot-limit", and the pivots made.

    On "ray" (no solution found by complementary pivoting: for P-matrix, positive
    semi-definite or copositive-plus M the LCP is infeasible) and "pivot-limit", z is the
    last point of the pivoting path, not a solution.
    """

    z: np.ndarray
    w: np.ndarray
    status: str
    pivots: int

    @property
    def success(self) -> bool:
        return self.status == "solved"


def lemke(M, q, max_pivots: int | None = None) -> LCPResult:
    """Solve 0 ≤ z ⊥ M z + q ≥ 0 by Lemke's method (module docstring).

    ``max_pivots``: pivot limit, default 50 + 20 n. M is n × n, q has n entries; both finite.
    """
    z, status, pivots, _, _ = run_lemke(M, q, max_pivots, None)  # validates M, q
    w = np.array(M, dtype=float, ndmin=2) @ z + np.array(q, dtype=float, ndmin=1)
    return LCPResult(z=z, w=w, status=STATUS[int(status)], pivots=int(pivots))


__all__ = ["lemke", "LCPResult"]
