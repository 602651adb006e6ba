"""The kernel that takes a Moreau–Jean run's kept samples from its window of rows
(moreau_jean_records.Collector): one compiled call a window, where numpy's calls over a short
run's row or two cost more than its steps (docs/performance.md, "The fixed cost of a call").
A module of its own: it imports nothing of the package but `_jit` and `direct_entry`, so that
an edit of the records' Python, or of what they import, leaves the compiled kernels' cache alone
(_jit's purge).
"""
from __future__ import annotations

import numpy as np

from .._jit import jit_borrowing
from .direct_entry import one_overload_entry


@jit_borrowing
def samples_into(ks, k_base, m0, origin, h, last, t_end, h_last, first, first_h, resumed, q, v, p_normal, p_tangent,
                 states, joint_impulse, contacts, columns, t, q_out, v_out, a, N, T, codes, joint_force):
    """The samples of global steps ks (window rows ks − k_base) into rows m0 … of the collector's
    t, q, v, a, N, T, codes, joint_force: the state at each; the records of the step that led to
    it over its size (a = Δv/h, N = p_N/h, T = p_T/h, the joints' impulses/h; the run's first
    state, which no step leads to: a NaN, N = T = 0, the modes of its first step). The step ending
    at k is h, h_last for the grid's last (when it is shortened), first_h (the resumed run's
    last step) for a resumed run's first. Records are every contact's: `contacts` have a column
    (`columns`, Window.columns), the others none (0). t: Grid.time's product and sum."""
    n_dof, n_contacts, n_joint = q.shape[1], N.shape[1], joint_impulse.shape[1]
    for j in range(ks.shape[0]):
        k, m = ks[j], m0 + j
        r = k - k_base
        t[m] = t_end if k == last else origin + float(k) * h
        for d in range(n_dof):
            q_out[m, d] = q[r, d]
            v_out[m, d] = v[r, d]
        for c in range(n_contacts):
            N[m, c] = 0.0
            T[m, c] = 0.0
            codes[m, c] = 0
        if r == 0:
            for d in range(n_dof):
                a[m, d] = np.nan
            for c in range(contacts.shape[0]):
                codes[m, contacts[c]] = states[0, columns[c]]
            for d in range(n_joint):
                joint_force[m, d] = 0.0
            continue
        h_k = h_last if h_last != 0.0 and k == last else h
        if resumed and k == first:
            h_k = first_h
        for d in range(n_dof):
            a[m, d] = (v[r, d] - v[r - 1, d]) / h_k
        for c in range(contacts.shape[0]):
            i, col = contacts[c], columns[c]
            N[m, i] = p_normal[r - 1, col] / h_k
            T[m, i] = p_tangent[r - 1, col] / h_k
            codes[m, i] = states[r - 1, col]
        for d in range(n_joint):
            joint_force[m, d] = joint_impulse[r - 1, d] / h_k


_ENTRY = None  # samples_into's one compiled overload's entry point, once known


def compiled_samples():
    """samples_into compiled: through its one overload's entry point once the dispatcher holds one
    (numba's overload search fingerprints its 27 arguments, ~1 µs of a short call), else the
    dispatcher. Its one caller (moreau_jean_records.Collector._samples) builds every argument the
    same way — the window's and the collector's C-contiguous arrays, int64 steps and contacts,
    Python numbers —, so the overload the first call compiled or loaded is every call's (as the
    loop's entry: integrators/direct_entry.py)."""
    global _ENTRY
    if _ENTRY is not None:
        return _ENTRY
    materialized = getattr(samples_into, "materialized", None)  # (a _jit.LazyKernel before numba loads)
    dispatcher = samples_into if materialized is None else materialized()
    _ENTRY = one_overload_entry(dispatcher)
    return dispatcher if _ENTRY is None else _ENTRY


__all__ = ["samples_into", "compiled_samples"]
