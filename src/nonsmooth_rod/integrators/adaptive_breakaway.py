"""Break-aways of error-controlled Moreau–Jean (`tol=`) decided by the smooth phase's prediction,
not by a step's overshoot. docs/error_control.md ("Break-away by the smooth phase") has the why
and the measurements.

A Moreau–Jean step holds a loaded contact with its Jacobian at the step's start: its ratio
p_T/p_N overshoots the exact T/N by ~0.16 h s⁻¹ beyond the error of the state itself, so near a
grazing peak of T/N a sticking contact breaks away early or wrongly, whatever the state's
accuracy. Here the contact modes of each window's start state (its last step's: open, stick,
slip±, where loaded) are integrated as the hybrid method does (`Hybrid.first_event`: its
Runge–Kutta steps, its watch, the event-driven reference's indicators), and the window is
planned on the first event they predict — by this point or an accepted one before it (a
predicted event stands: near a grazing peak, later states' T/N may fall a round-off below μs):

* none before the window's end: its sticking contacts are held through it (μs and μd raised to
  (1 + HOLD_FRACTION) μs for the window);
* a sticking contact's break-away, or a sliding contact's slip reversal (slip-zero): windows
  halving the time left approach it (APPROACH) and the last, at most an event window long,
  ends there, held;
* at a break-away (within RELEASE_STEPS fine event steps of it) the window releases the contact
  (μs lowered to μd: the exact law has broken it away there) and holds the others;
* at a slip reversal it holds the contact if its stick mode does not break away at once (the
  reference's rule: stick first) — until that mode's first event —, else leaves it to the
  step's law;
* any other event first (a touchdown, a lift-off): no contact is held, the window as the
  controller chose it.

A window that ends with a held contact open is redone in halves (`contradicted`). Scenes the
hybrid method does not run (other contacts than disks on lines, driven things) hold nothing:
the step's law decides, as it did.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.packing import C_MU_D, C_MU_S
from ..solvers.problem import STATE_OPEN, STATE_STICK
from ..solvers.two_coefficient import STATE_NAMES
from .accumulation import _projection
from .hybrid import Hybrid, HybridOptions, handles

# A held contact's μs and μd for a window are (1 + HOLD_FRACTION) μs: above what its step's ratio
# overshoots (0.22 h s⁻¹ at the window's fine steps, ≤ 3.4e-5 at the default h), and μd too, so
# that a contact the step lets open and strike again for a few steps (the gap's creep near a
# break-away: an artefact of the step, docs/error_control.md) sticks again at once; and small,
# so that a loaded contact's step problem keeps its unique solution (a wide friction interval
# can admit several: Painlevé).
HOLD_FRACTION = 0.03
# The prediction's Runge–Kutta step at most (the hybrid method at 1e-2 s locates the rod's
# events to 1.2e-8 s, docs/error_control.md), and at most the largest window.
PREDICTION_STEP = 1e-2
# A planned event within this many fine steps of an event window (tol/2 each) is at hand: the
# window starting there acts on it (a window cut shorter would locate it no better).
RELEASE_STEPS = 1.0
BREAKS = ("break-upper", "break-lower")
PLANNED = BREAKS + ("slip-zero",)  # the events a window is planned to end at
# A planned event closer than APPROACH windows is approached by windows halving the time left to
# it, down to an event window (h_event), which ends at it: consecutive windows then differ by at
# most a factor 2 (adaptive.GRADING), on both sides of the event. A step shorter than the one
# before reads the longer steps' residual relative velocity as a force spike: after a window of
# 1e-2 s, an event window of 3.2e-4 s opened the rod's ball A at its slip reversal.
APPROACH = 3.0


@dataclass(frozen=True)
class Window:
    """A window as the smooth phase decides it: its length, the contacts it holds, those it lets
    slide from its start (a break-away predicted there), and whether it ends at a predicted one."""

    H: float
    held: tuple = ()
    released: tuple = ()
    cut: bool = False


class BreakAways:
    """Which contacts a window holds or releases, and where a predicted break-away ends it."""

    def __init__(self, scene, model, tol: float, h_event: float, largest_window: float, t_end: float):
        """h_event: the controller's longest event window."""
        self.scene, self.contacts, self.t_end, self.h_event = scene, model.contacts, t_end, h_event
        self.horizon, self.release = APPROACH * largest_window, RELEASE_STEPS * tol / 2
        self.hybrid = Hybrid(HybridOptions(h=min(largest_window, PREDICTION_STEP))) if handles(scene) else None
        self._ahead = {}  # id(point) → (point, its prediction): a point is predicted once
        self.predictions = 0

    def window(self, points: list, H: float) -> Window:
        """The window from the last of the accepted `points` for a window of H the controller asks."""
        point = points[-1]
        loaded, held = self._loaded(point)
        if not loaded:
            return Window(H)
        ahead, planned = self._predicted(point), self._planned(points, loaded, held)
        if planned is not None and planned[0] - point.t <= self.release:
            if planned[1] in BREAKS:
                return Window(min(H, self.h_event), tuple(i for i in held if i != planned[2]), (planned[2],))
            stuck = self._stuck(point, planned[2])  # a slip reversal at hand
            if stuck is not None:  # the exact law sticks there, until the stick mode's first event
                return self._toward(min(H, self.h_event), stuck - point.t, held + (planned[2],))
            planned = None
        reach = point.t + APPROACH * H
        if ahead is not None and ahead[1] not in PLANNED and ahead[0] < min(reach, planned[0] if planned else reach):
            return Window(H)  # another event first: the step's law decides, as without a prediction
        if planned is None or planned[0] >= reach:
            return Window(H, held)
        return self._toward(H, planned[0] - point.t, held)

    def _toward(self, H: float, to_event: float, held: tuple) -> Window:
        """A held window of at most H towards an event `to_event` ahead: ending there if that is
        within H and an event window, else halving the time left (graded, APPROACH)."""
        if to_event <= min(H, self.h_event):
            return Window(to_event, held, cut=True)
        return Window(min(H, to_event / 2), held)

    def _planned(self, points: list, loaded: tuple, held: tuple):
        """(t, kind, contact): the earliest break-away of a held contact or slip reversal of a
        loaded one, not yet passed, that the point or an accepted point before it (within the
        horizon) predicted. A predicted event stands: near a grazing peak (μs = max T/N − 1e-6)
        the exact T/N of the states reached later may fall a round-off below μs (their velocity
        error, ~3e-7 at tol = 1e-5), and the break would then never come."""
        now, found = points[-1].t, []
        for p in reversed(points):
            if p.t < now - self.horizon:
                break
            ahead = self._ahead.get(id(p), (None, None))[1]
            if ahead is not None and ahead[0] > now - self.release and (
                    ahead[2] in held if ahead[1] in BREAKS else ahead[1] == "slip-zero" and ahead[2] in loaded):
                found.append(ahead)
        return min(found, default=None)

    def contradicted(self, window: Window, end_states) -> bool:
        """Whether a held contact ends the window open (the states of its last step): the smooth
        phase has it stay closed, and near a break-away the step lets a loaded contact's gap creep
        open until it flies for a few steps and strikes again (docs/error_control.md) — a window
        ending in that flight is redone in halves. (One ending in a slide is kept: a slide the
        step cannot help, a residual relative velocity read as a force by shorter steps, is only
        made worse by halving.)"""
        return any(int(end_states[i]) == STATE_OPEN for i in window.held)

    def holding(self, window: Window):
        """A context in which the window's held contacts' μs is raised in the packed table and its
        released ones' lowered to μd (restored after: the table may be shared by the runs of a
        scene, integrators/scene_plans.py)."""
        return Held(self.contacts, window.held, window.released)

    def _loaded(self, point) -> tuple[tuple, tuple]:
        """The contacts loaded in the step reaching the point, and those of them that stick (none
        where the scene is not the hybrid method's, or at a fresh start)."""
        codes, p_normal = point.records[3], point.records[0]
        if self.hybrid is None or np.any(codes < 0):
            return (), ()
        loaded = (codes != STATE_OPEN) & (p_normal > 0.0)
        return (tuple(int(i) for i in np.nonzero(loaded)[0]),
                tuple(int(i) for i in np.nonzero(loaded & (codes == STATE_STICK))[0]))

    def _predicted(self, point, sticking: int | None = None):
        """The first event of the point's modes (`sticking`: that contact's mode taken as stick)."""
        key = id(point) if sticking is None else (id(point), sticking)
        if key not in self._ahead:
            modes = [STATE_NAMES[int(c)] for c in point.records[3]]
            if sticking is not None:
                modes[sticking] = "stick"
            v = consistent_velocity(self.scene, point.q, point.v, modes)
            t_end = min(point.t + self.horizon, self.t_end)
            self._ahead[key] = (point, self.hybrid.first_event(self.scene, point.t, point.q, v, modes, t_end))
            self.predictions += 1
        return self._ahead[key][1]

    def _stuck(self, point, contact: int) -> float | None:
        """Where a sliding contact whose slip reverses at the point sticks (the event-driven
        reference's rule: stick first, where μs holds): None if its stick mode breaks away at
        once, else the time of that mode's first event (inf: none within the horizon)."""
        ahead = self._predicted(point, contact)
        if ahead is None:
            return math.inf
        if ahead[1] in BREAKS and ahead[2] == contact and ahead[0] - point.t <= self.release:
            return None
        return max(ahead[0], point.t + self.release)


def consistent_velocity(scene, q, v, modes) -> np.ndarray:
    """v projected M-orthogonally onto the modes' velocity constraints: no normal velocity of a
    closed contact, no slip of a sticking one. A Moreau–Jean state leaves them O(h) (the step's
    Jacobian is its start's); the modes' equations keep what they are given."""
    rows, targets = [], []
    for i, mode in enumerate(modes):
        if mode == "open":
            continue
        kin = scene.contacts[i].kinematics(q, v, scene.n_dof)
        rows.append(kin.H_N)
        targets.append(0.0)
        if mode == "stick":
            rows.append(kin.H_T)
            targets.append(kin.surface_velocity)
    if not rows:
        return v
    H = np.array(rows)
    residual = H @ v - np.array(targets)
    if not residual.any():  # consistent already (a run's exact start): its projection is zero
        return v
    return v - _projection(scene.inverse_mass_diagonal, H, residual)


class Held:
    """The packed table with a window's held contacts' friction raised and its released ones' μs lowered
    to μd, restored on leaving (the table may be shared by the runs of a scene)."""

    def __init__(self, table, held: tuple, released: tuple):
        self.table, self.held, self.released = table, list(held), list(released)

    def __enter__(self):
        self.saved = self.table[:, [C_MU_S, C_MU_D]].copy()
        self.table[self.held, C_MU_S] *= 1.0 + HOLD_FRACTION
        self.table[self.held, C_MU_D] = self.table[self.held, C_MU_S]
        self.table[self.released, C_MU_S] = self.table[self.released, C_MU_D]

    def __exit__(self, *exc):
        self.table[:, [C_MU_S, C_MU_D]] = self.saved
        return False
