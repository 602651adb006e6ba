"""What a Moreau–Jean run keeps, gathered while it runs, and the state it ends in.

The compiled loop writes its per-step records into a window of rows (moreau_jean_loop's `out`
arrays, `chunk` steps long after `HISTORY` rows of the steps before). Between windows,
`Collector.take` keeps from them only what the result needs:

* the samples the result keeps (every step, or one per `save_every`): t, q, v, a, N, T, modes;
* each contact's runs of one state (start step, state code) — the phases, exactly;
* around each state change, the rows its boundary is located from (`located_phases` reads the
  impulses of the 4 steps before it and the slip velocity at the 4 states before it);
* the impacts, with the rows around them.

So memory follows what is kept, not the number of steps, and a stop condition can be tried
between windows. The window's per-contact records have a column only for the contacts that have
been candidates (moreau_jean_loop.new_records: found contacts list hundreds that never come
near); what is taken from them is every contact's (`Window.full`), those without a column
holding the records of a contact out of reach. `ResumeState` is what the next step reads from
the steps before it — q, v, the contact memory (closed, grazing, slip signs) and the last
HISTORY rows of records (warm starts, phase location) — with the step grid (origin, index): a
restart continues the very same floats.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..solvers._common import interpreted
from . import moreau_jean_loop as loop
from .kept_samples import compiled_samples, samples_into
from .sampling import save_slots

# Rows of records a window keeps from the steps before its first: the warm start reads one, the
# location of a phase boundary at step k reads steps k − 4 … k − 1 (moreau_jean._boundary_offset).
HISTORY = 4
# The largest window (steps): its rows cost 16 n_dof + 32 bytes a step per record column (at most
# n_contacts: moreau_jean_loop.new_records).
MAX_CHUNK = 1 << 16
# Work arrays of moreau_jean_loop that carry a contact's memory from one step to the next.
WORK_CLOSED, WORK_GRAZING, WORK_SLIP_SIGN = 5, 6, 7
RECORDS = ("p_normal", "p_tangent", "slip", "states")  # out[2] … out[5]
FEW_CHANGES = 16  # state changes in a window up to which their rows are found in Python
FEW_CONTACTS = 64  # contacts up to which a window's columns are checked in Python first
_COUNTING = [list(range(1, n + 1)) for n in range(FEW_CONTACTS + 1)]  # each contact's column + 1, in order
# Window.columns where every contact's column is its index: (contacts, columns, True), one per count,
# shared by every window (only read: indices into records and contacts)
_IDENTITY = [(np.arange(n), np.arange(n), True) for n in range(FEW_CONTACTS + 1)]


@dataclass
class ResumeState:
    """The state a Moreau–Jean step reads: q, v, contact memory and the last records.

    origin, step: the step grid, t_k = origin + k h (step: the index of the end state);
    on_grid: the run ended on that grid (its last step was a whole h), so a restart goes on
    with the same k; last_h: the size of the last step; q, v: the last HISTORY + 1 states (the
    end state last); p_normal, p_tangent, slip, states: the records of the last HISTORY steps;
    was_closed, grazing, slip_sign: per contact, as moreau_jean_loop keeps them.
    """

    origin: float
    step: int
    h: float
    on_grid: bool
    last_h: float
    q: np.ndarray
    v: np.ndarray
    p_normal: np.ndarray
    p_tangent: np.ndarray
    slip: np.ndarray
    states: np.ndarray
    was_closed: np.ndarray
    grazing: np.ndarray
    slip_sign: np.ndarray

    def as_dict(self) -> dict:
        """JSON-ready (floats round-trip exactly through json)."""
        return {"method": "moreau-jean", "origin": float(self.origin), "step": int(self.step), "h": float(self.h),
                "on_grid": bool(self.on_grid), "last_h": float(self.last_h),
                **{name: np.asarray(getattr(self, name)).tolist() for name in _ARRAYS}}

    @classmethod
    def from_dict(cls, d: dict, n_dof: int, n_contacts: int) -> "ResumeState":
        rows = {name: np.asarray(d[name], dtype=np.int64 if name in _INT_ARRAYS else float) for name in _ARRAYS}
        for name in ("q", "v"):
            rows[name] = rows[name].reshape(-1, n_dof)
        for name in RECORDS:  # one row per step before the end state (a scene may have no contacts)
            rows[name] = rows[name].reshape(rows["q"].shape[0] - 1, n_contacts)
        return cls(float(d["origin"]), int(d["step"]), float(d["h"]), bool(d["on_grid"]), float(d["last_h"]),
                   **rows)


_ARRAYS = ("q", "v", "p_normal", "p_tangent", "slip", "states", "was_closed", "grazing", "slip_sign")
_INT_ARRAYS = ("states", "was_closed", "grazing")


@dataclass
class Grid:
    """The steps of a run: t_k = origin + k h for k = first … first + n_full, then (when t_end
    is not on the grid) one last step of h_last ending exactly at t_end."""

    origin: float
    first: int
    n_full: int
    h: float
    h_last: float  # 0: none
    t_end: float

    @classmethod
    def of(cls, h: float, t0: float, t_end: float, resume: ResumeState | None) -> "Grid":
        origin, first = t0, 0
        if resume is not None and resume.on_grid and resume.h == h:
            origin, first = resume.origin, resume.step
        span = (t_end - origin) / h - first
        n = max(1, int(math.ceil(span - 1e-9)))
        if abs(span - n) <= 1e-9:
            return cls(origin, first, n, h, 0.0, t_end)
        t_before = origin + (first + n - 1) * h
        return cls(origin, first, n - 1, h, t_end - t_before, t_end)

    def __post_init__(self):
        # plain attributes, computed once: a grid is never changed after Grid.of, a run reads them a
        # dozen times, and a cached property's first read (its lock) costs more than computing both
        self.n_steps: int = self.n_full + (1 if self.h_last else 0)
        self.last: int = self.first + self.n_steps
        self.reached = f"reached t_end = {self.t_end:g} s"  # a run's message then (formatted once a grid)

    def time(self, k: np.ndarray | int):
        """Times of global step indices (the last one: t_end exactly)."""
        if isinstance(k, (int, np.integer)):
            return self.t_end if k == self.last else self.origin + float(k) * self.h
        t = self.origin + np.asarray(k, dtype=float) * self.h
        return np.where(np.asarray(k) == self.last, self.t_end, t)


class Window:
    """The loop's out arrays for `chunk` steps after HISTORY rows of the steps before.

    Row r holds the state at step k_base + r and the records of the step leaving it."""

    def __init__(self, n_dof: int, n_contacts: int, chunk: int, joint_rows: int = 0, out=None, columns=None,
                 slip_default=None):
        """`out`: zeroed records of this shape lent by an earlier run (integrators/scene_plans.py);
        `columns`: the record columns to start with (None: one a contact, new_records), widened
        when the candidates need more; `slip_default`: the slip record of a contact out of reach
        (−its belt's surface velocity, as the loop writes it; default −0.0)."""
        rows = HISTORY + chunk
        capacity = chunk + 4 * n_contacts  # impacts in one window: at most one per contact per step
        self.out = loop.new_records(n_dof, n_contacts, rows, capacity, joint_rows, columns) if out is None else out
        self.rows, self.k_base, self.r = rows, 0, 0
        self._columns = None  # (the column array, columns given, columns(), owners()) last found
        self.defer_rows = False  # the last take leaves its state runs and rows to Collector.settle_rows
        self.slip_default = np.full(n_contacts, -0.0) if slip_default is None else slip_default

    def seed(self, q0, v0, first: int, resume: ResumeState | None) -> None:
        q, v = self.out[0], self.out[1]
        if resume is None:
            q[0], v[0], self.r = q0, v0, 0
        else:
            m = resume.states.shape[0]
            q[: m + 1], v[: m + 1] = resume.q, resume.v
            self._seed_records([getattr(resume, name) for name in RECORDS], m)
            self.r = m
        self.k_base = first - self.r

    def _seed_records(self, rows: list, m: int) -> None:
        """The resumed history's records (every contact's, RECORDS order) into rows 0 … m − 1: a
        column for each contact whose records are not those of a contact out of reach (bit for
        bit: a slip of 0.0 is not −0.0); the others get theirs when they are candidates."""
        column = self.out[loop.O_COLUMN]
        n = column.shape[0] - 1
        p_normal, p_tangent, slip, states = rows
        own = ((p_normal != 0.0).any(axis=0) | (p_tangent != 0.0).any(axis=0) | (states != 0).any(axis=0)
               | (slip.view(np.int64) != self.slip_default.view(np.int64)).any(axis=0))
        new = np.flatnonzero(own & (column[:n] == 0))
        while column[n] + new.size > self.out[2].shape[1]:
            self.widen()
            column = self.out[loop.O_COLUMN]
        column[new] = column[n] + 1 + np.arange(new.size)
        column[n] += new.size
        contacts, cols, _ = self.columns()
        for j, a in enumerate(rows):
            self.out[2 + j][:m, cols] = a[:, contacts]

    def widen(self) -> None:
        """Twice the record columns (at most one a contact), every row so far kept: a new candidate
        found them all taken (moreau_jean_loop.RUN_RECORDS_SHORT)."""
        old = self.out
        n_contacts, width = old[loop.O_COLUMN].shape[0] - 1, old[2].shape[1]
        new = loop.new_records(old[0].shape[1], n_contacts, self.rows, old[6].shape[0],
                               old[loop.O_JOINT_IMPULSE].shape[1], min(n_contacts, max(1, 2 * width)))
        for a, b in zip(old, new):
            if a.shape == b.shape:
                b[...] = a
            else:  # a per-contact record
                b[:, :width] = a
        self.out = new

    def columns(self):
        """(contacts, columns, whether every contact's column is its index): the contacts that have
        a column of the records, in order, and their columns. Kept while no column is given: a
        column is never taken back, so the count of columns given (column[n]) names the mapping."""
        column = self.out[loop.O_COLUMN]
        n = column.shape[0] - 1
        given = int(column[n])
        kept = self._columns
        if kept is not None and kept[0] is column and kept[1] == given:
            return kept[2]
        if given == n and n <= FEW_CONTACTS and column[:n].tolist() == _COUNTING[n]:
            found = _IDENTITY[n]  # every contact's column its index (declared contacts): no search
            owner = found[0]
        else:
            contacts = np.flatnonzero(column[:n])
            cols = column[contacts] - 1
            found = contacts, cols, contacts.size == n and bool(np.all(cols == contacts))
            owner = np.empty(contacts.size, dtype=np.int64)
            owner[cols] = contacts
        self._columns = (column, given, found, owner)
        return found

    def owners(self) -> np.ndarray:
        """The contact of each column given, in column order (the order they were given in)."""
        self.columns()
        return self._columns[3]

    def full(self, which: int, rows):
        """Record `which` (2 … 5: p_normal, p_tangent, slip, states) at `rows` (an index, a slice,
        an array) for every contact: those without a column hold a contact out of reach's records
        (0, or slip_default). A view when every contact has its own column in order."""
        a = self.out[which]
        contacts, cols, identity = self.columns()
        if identity:
            return a[rows]
        part = a[rows][..., cols]
        every = np.empty(part.shape[:-1] + (self.slip_default.shape[0],), dtype=a.dtype)
        every[...] = self.slip_default if which == 4 else 0
        every[..., contacts] = part
        return every

    def room(self) -> int:
        return self.rows - self.r

    def slide(self) -> None:
        """Move the last HISTORY rows to the top: the next window's steps read them."""
        keep = min(HISTORY, self.r)
        lo = self.r - keep
        for a in self.out[:2]:
            a[: keep + 1] = a[lo: self.r + 1]
        for a in self.out[2:6] + (self.out[loop.O_JOINT_IMPULSE],):
            a[:keep] = a[lo: self.r]
        self.k_base += lo
        self.r = keep

    def resume_state(self, grid: Grid, work, last_h: float, on_grid: bool) -> ResumeState:
        r, out = self.r, self.out
        lo = r - min(HISTORY, r)
        records = (np.array(self.full(j, slice(lo, r))) for j in range(2, 6))
        return ResumeState(grid.origin if on_grid else grid.t_end, self.k_base + r if on_grid else 0, grid.h,
                           on_grid, last_h, out[0][lo: r + 1].copy(), out[1][lo: r + 1].copy(), *records,
                           work[WORK_CLOSED].copy(), work[WORK_GRAZING].copy(), work[WORK_SLIP_SIGN].copy())


def _spread(part: np.ndarray, positions: np.ndarray, width: int) -> np.ndarray:
    """Rows of records of some contacts (`part`) placed at `positions` of rows `width` wide, zeros elsewhere."""
    spread = np.zeros((part.shape[0], width), dtype=part.dtype)
    spread[:, positions] = part
    return spread


def kept_steps(grid: Grid, lo: int, hi: int, save_every: float | None) -> np.ndarray:
    """Global steps in [lo, hi] the result keeps: the first of the run, then one per save_every
    (the first step of each slot of the common origin) and the run's last."""
    k = np.arange(lo, hi + 1)
    if save_every is None:
        return k
    slot = save_slots(k * grid.h, save_every)
    keep = slot != save_slots((k - 1) * grid.h, save_every)
    keep |= (k == grid.first) | (k == grid.last)
    return k[keep]


def count_kept(grid: Grid, save_every: float | None) -> int:
    if save_every is None:
        return grid.n_steps + 1
    total, k = 0, grid.first
    while k <= grid.last:  # in blocks of a window's size: no array of every step
        hi = min(grid.last, k + MAX_CHUNK)
        total += kept_steps(grid, k, hi, save_every).size
        k = hi + 1
    return total


def compile_samples() -> None:
    """samples_into compiled with the types a run passes it (a window's arrays and a collector's):
    where the loop compiles, under its notice (moreau_jean.Engine.compiling), not after it."""
    grid = Grid.of(1.0, 0.0, 1.0, None)
    window, collector = Window(3, 1, 1), Collector(grid, 3, 1, None, None)
    collector._samples(window, np.arange(2), True)


class Collector:
    """The samples, state runs, boundary rows and impact rows of a run, taken window by window."""

    def __init__(self, grid: Grid, n_dof: int, n_contacts: int, save_every: float | None,
                 resume: ResumeState | None, joint_rows: int = 0):
        n = count_kept(grid, save_every)
        self.joint_force = np.empty((n, joint_rows))  # each kept step's joint impulses / h
        self.grid, self.save_every, self.resume = grid, save_every, resume
        self.t, self.q, self.v, self.a = np.empty(n), np.empty((n, n_dof)), np.empty((n, n_dof)), np.empty((n, n_dof))
        self.N, self.T = np.empty((n, n_contacts)), np.empty((n, n_contacts))
        self.codes = np.empty((n, n_contacts), dtype=np.int8)  # (every row written by samples_into)
        self.n = 0
        # each contact's runs of one state, (first step, code): made when the first rows are taken
        self.runs: list[list[tuple[int, int]]] = []
        self._blocks: list[tuple] = []  # (steps, q, v, p_normal, p_tangent, states, records valid) around changes
        self._index = None
        self.impact_rows: list[tuple] = []  # (step, contact, t, q_k, v_k, v_k+1, p_n, p_t)
        self._codes_before = None
        self._pending_rows = None  # (window, k_from, k_to) of the last take, until settle_rows

    def take(self, window: Window, k_from: int, k_to: int, final: bool, compiled: bool = False) -> None:
        """Steps k_from … k_to − 1 are done (states k_from … k_to in the window); `final`: the run
        ends at k_to; `compiled`: the samples are taken by the compiled kernel (the run's steps are:
        moreau_jean.Engine), else by its interpreted twin."""
        lo = k_from + 1 if self.n else k_from
        if self.save_every is None:  # every step kept: lo … k_to
            ks = np.arange(lo, k_to + 1)
        else:
            ks = kept_steps(self.grid, lo, k_to, self.save_every)
            if final and (ks.size == 0 or ks[-1] != k_to):
                ks = np.r_[ks, k_to]
        if ks.size:
            self._samples(window, ks, compiled)
        if final and window.defer_rows:  # read only to locate phases: taken on first need (`settle_rows`)
            self._pending_rows = (window, k_from, k_to)
        else:
            self._runs_and_rows(window, k_from, k_to)
        self._impacts(window)

    def settle_rows(self) -> None:
        """The state runs and boundary rows of the run's last window, taken on first need: when
        the phases are located, or before the window's arrays go to another run (its result's end
        state is built then: moreau_jean._result). A short run's result whose phases nobody
        reads never takes them."""
        pending = self._pending_rows
        if pending is not None:
            self._pending_rows = None
            self._runs_and_rows(*pending)

    def _samples(self, window: Window, ks: np.ndarray, compiled: bool) -> None:
        """The samples of global steps ks (increasing, in the window) at the next rows (one
        compiled call: a short run's numpy calls over a row or two cost more than its steps)."""
        out, grid, resume = window.out, self.grid, self.resume
        contacts, columns, _ = window.columns()
        take = compiled_samples() if compiled else interpreted(samples_into)
        take(ks, window.k_base, self.n, grid.origin, grid.h, grid.last, grid.t_end, grid.h_last, grid.first,
             grid.h if resume is None else resume.last_h, resume is not None, out[0], out[1], out[2], out[3],
             out[5], out[loop.O_JOINT_IMPULSE], contacts, columns, self.t, self.q, self.v, self.a, self.N, self.T,
             self.codes, self.joint_force)
        self.n += ks.size

    def _runs_and_rows(self, window: Window, k_from: int, k_to: int) -> None:
        out = window.out
        first = self._codes_before is None
        r_lo = 0 if first else k_from - window.k_base  # a resumed run: from its history
        codes = out[5][r_lo: k_to - window.k_base]
        if not codes.shape[0]:
            return
        owner = window.owners()  # the contact of each column given
        codes = codes[:, :owner.size]  # (a view: the columns given)
        n, k0 = self.N.shape[1], window.k_base + r_lo
        before = np.zeros(n, dtype=codes.dtype) if first else self._codes_before  # every contact's
        changed = np.empty(codes.shape, dtype=bool)
        np.not_equal(codes[1:], codes[:-1], out=changed[1:])
        np.not_equal(codes[0], before[owner], out=changed[0])
        if first:  # every contact's first run starts here (one without a column: open)
            start = before.copy()
            start[owner] = codes[0]
            self.runs = [[(k0, code)] for code in start.tolist()]
            changed[0] = False
        at, columns = np.nonzero(changed)  # every change, by row then column (a row of balls: ~100 a run)
        for i, k, code in zip(owner[columns].tolist(), (at + k0).tolist(), codes[at, columns].tolist()):
            self.runs[i].append((k, code))
        rows_changed = np.unique(at).tolist()
        if first and n:
            rows_changed.insert(0, 0)
        if rows_changed:
            self._keep_rows(window, [k0 + m for m in rows_changed], k_to, owner)
        self._codes_before = before.copy()
        self._codes_before[owner] = codes[-1]

    def _keep_rows(self, window: Window, steps: list, k_to: int, owner) -> None:
        """The rows of steps k − HISTORY … k for each state change at step k, as arrays (a
        contact that chatters changes every step: its rows cost what the per-step records did);
        the records of the columns given (`owner`: their contacts)."""
        out, lo = window.out, window.k_base
        if len(steps) <= FEW_CHANGES:  # (a set of a few rows: cheaper than numpy's unique)
            need = np.array(sorted({j for k in steps for j in range(max(k - HISTORY, lo), min(k, k_to) + 1)}),
                            dtype=np.int64)
        else:
            need = np.unique((np.array(steps)[:, None] - np.arange(HISTORY + 1)[None, :]).ravel())
            need = need[(need >= lo) & (need <= k_to)]
        r = need - lo
        rec, given = np.minimum(r, out[2].shape[0] - 1), owner.size
        self._blocks.append((need, out[0][r], out[1][r], out[2][rec, :given], out[3][rec, :given],
                             out[5][rec, :given], need < k_to, owner))
        self._index = None

    def _row(self, j):
        """(q, v, p_normal, p_tangent, states) of global step j (records None if not kept; of the
        contacts with a column, at `_position`), or None."""
        if self._index is None:
            self._index_blocks()
        steps = self._index[0]
        m = int(np.searchsorted(steps, j))
        if m == steps.size or steps[m] != j:
            return None
        q, v, pn, pt, st, valid = (a[m] for a in self._index[1:])
        return (q, v, pn, pt, st) if valid else (q, v, None, None, None)

    def _index_blocks(self) -> None:
        """The kept rows by step, each block's records spread over the columns the last has (a
        column is never taken back: the last block's columns hold every earlier one's)."""
        every = self._blocks[-1][-1] if self._blocks else np.zeros(0, dtype=np.int64)
        self._position = np.full(self.N.shape[1], -1)
        self._position[every] = np.arange(every.size)
        blocks = [b[:3] + tuple(_spread(a, self._position[b[-1]], every.size) for a in b[3:6]) + (b[6],)
                  for b in self._blocks]
        columns = list(zip(*blocks)) if blocks else [np.zeros(0, dtype=np.int64)] + [np.zeros(0)] * 6
        steps, *arrays = (np.concatenate(b) for b in columns)
        # a step kept twice (the last of one window, again in the next): its later copy has its records
        order = np.lexsort((arrays[-1], steps))
        last = np.r_[steps[order][1:] != steps[order][:-1], True]
        self._index = (steps[order][last], *(a[order][last] for a in arrays))

    def _impacts(self, window: Window) -> None:
        out = window.out
        counters = out[9]
        count = int(counters[loop.K_N_IMPACTS])
        if not count:  # (most windows of a short run)
            return
        for n in range(count):
            r, i = int(out[7][n]), int(out[8][n])
            self.impact_rows.append((window.k_base + r, i, float(out[6][n]), out[0][r].copy(), out[1][r].copy(),
                                     out[1][r + 1].copy(), np.array(window.full(2, r)), np.array(window.full(3, r))))
        counters[loop.K_N_IMPACTS] = 0

    def trajectory_arrays(self):
        n = self.n
        if n == self.t.shape[0]:  # every sample taken (the common case): the arrays themselves
            return self.t, self.q, self.v, self.a, self.N, self.T, self.codes
        return self.t[:n], self.q[:n], self.v[:n], self.a[:n], self.N[:n], self.T[:n], self.codes[:n]

    # What located_phases reads, by global step (NaN / −1 where the run has no such row; a contact
    # without a column of the records: those of a contact out of reach).
    def _record(self, j, i, which, missing):
        row = self._row(j)
        if row is None or row[which] is None:
            return missing
        at = self._position[i]
        return row[which][at] if at >= 0 else 0

    def p_normal(self, j, i):
        return float(self._record(j, i, 2, math.nan))

    def p_tangent(self, j, i):
        return float(self._record(j, i, 3, math.nan))

    def state(self, j, i):
        return int(self._record(j, i, 4, -1))

    def qv(self, j):
        row = self._row(j)
        return None if row is None else (row[0], row[1])
