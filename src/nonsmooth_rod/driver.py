"""The one driver: `simulate(scene, q0, v0, t_end, method=..., **options)`.

In the spirit of scipy's `solve_ivp` and diffrax's `diffeqsolve`: one call, the method picked
by name, its options passed through by keyword, one result type whatever the method. The
driver validates everything once (the state, the times, the options, whether the method
handles the scene, whether the output fits in memory) from what each integrator declares
(its `declares`, integrators/declaration.py), so the integrators — and the compiled loop — can
trust their inputs; it never asks which method it runs.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from . import _jit
from .integrators import METHODS, MAX_OUTPUT_BYTES, check_output_size, integrator_class
from .model.scene import Scene
from .results import SimulationResult
from .validation import InputError, quoted, require_finite, require_positive, require_states


@dataclass(frozen=True)
class StopAtImpact:
    """Stop condition: end the run at the first impact of the named contact."""

    contact: str


class RunSetup(NamedTuple):
    """What a result was run with (`result.setup`), by the caller's names: what `result.restart`
    runs again and what a saved result describes (result_files)."""

    scene: Scene
    method: str
    options: dict
    stop: object
    save_every: float | None
    q0: np.ndarray
    v0: np.ndarray
    t0: float
    t_end: float


def simulate(scene: Scene, q0, v0, t_end: float, method: str = "moreau-jean", *, t0: float = 0.0,
             save_every: float | None = None, stop=None, resume=None, **options) -> SimulationResult:
    """Simulate `scene` from (q0, v0) at time t0 to exactly t_end with the named method.

    method: "moreau-jean" (options h, theta, solver, solver_options, activation_gamma,
    min_phase, fast, tol), "event-driven" (rtol, atol, ode_method, max_step, output_dt, ...),
    "hybrid" (h, order 2–4: fixed explicit Runge–Kutta steps in each smooth mode, the
    event-driven reference's events between them; a body's disks and points on fixed lines) or
    "regularized" (epsilon, friction_curve, ode_method, rtol, atol, stiffness, damping,
    time_limit, ...): each integrator's options dataclass (its `declares.options`).
    save_every: keep one sample per this many seconds (default: every step / output_dt); every
    method thins while it runs, so memory follows what is kept.
    stop: a contact name or `StopAtImpact(name)` (the run ends at that contact's first
    impact), a callable (t, q, v) -> bool (tried at each kept sample while the run goes: it
    ends at the first where one is true, status "stopped"), or a list of these.
    resume: the `end_state` of an earlier Moreau–Jean result (what its next step reads: contact
    memory, warm starts, the step grid): the run goes on exactly as the earlier one would have
    (but for a break-away confirmed by the smooth phase in a stick that spans the resume: it is
    predicted from the resumed run's first state, not the stick's start, docs/friction.md);
    `result.restart(t_end)` passes it.
    Bad input raises InputError naming the argument; a run that fails returns a result with
    status "failed" and a message saying where and why.
    """
    if not isinstance(scene, Scene):
        raise InputError(f"scene must be a nonsmooth_rod.Scene, got {type(scene).__name__}")
    q0, v0 = require_states(q0, v0, scene.n_dof)
    t0 = t0 if type(t0) is float and math.isfinite(t0) else require_finite("t0", t0)  # (a float: no call)
    t_end = t_end if type(t_end) is float and math.isfinite(t_end) else require_finite("t_end", t_end)
    if t_end <= t0:
        raise InputError(f"t_end must be later than t0 = {t0:g}, got {t_end!r}")
    if save_every is not None:
        save_every = require_positive("save_every", save_every)
    integrator_cls = _integrator_class(method)
    declared = integrator_cls.declares
    _check_contacts(method, declared, scene)
    impact_stops, callables = _stop_conditions(stop, scene)
    opts = _options(declared.options, method, options, impact_stops)
    _check_refusals(method, declared, scene, opts, t_end - t0)
    _check_output_size(declared, opts, t_end - t0, save_every, scene)
    if not _jit.HAVE_NUMBA and declared.compiles is not None and declared.compiles(opts):
        _jit.warn_once_without_numba()  # said once
    if resume is not None:
        if declared.resumes is None:
            raise InputError(f"resume: only a Moreau–Jean run continues from an end state; method "
                             f"{method!r} restarts from (q0, v0)")
        declared.resumes(resume, scene, q0, v0)
    # On the scene's clock; each method keeps one sample per save_every and tries the stop
    # conditions at them while it runs (integrators/sampling.py).
    result = integrator_cls(opts).run(scene, q0, v0, t_end, t0=t0, resume=resume, save_every=save_every,
                                      stop=callables)
    result.method = method
    result.setup = RunSetup(scene, method, options, stop, save_every, q0, v0, t0, t_end)  # (options: this call's own dict)
    return result


def _integrator_class(method):
    try:  # (integrator_class keeps each class: one lookup a call)
        return integrator_class(method)
    except (KeyError, TypeError):  # an unknown name, or not a name at all
        raise InputError(f"unknown method {quoted(method)}; choose from: {', '.join(METHODS)}") from None


def _check_contacts(method: str, declared, scene: Scene) -> None:
    """Refuse, by name, a contact relation the method does not run."""
    handled = declared.contacts
    for contact in scene.contacts:
        if type(contact).__name__ not in handled:
            raise InputError(f"method {method!r} does not handle {type(contact).__name__} contacts "
                             f"(contact {contact.name!r}); it handles {', '.join(handled)}")


_SIZES_CHECKED: dict = {}  # (options, duration, save_every, dofs, contacts) whose output fits: checked once


def _check_output_size(declared, opts, duration: float, save_every, scene: Scene) -> None:
    """Refuse a run whose samples cannot fit (check_output_size); a call that repeats a checked
    one (the same options object, duration, save_every, and scene size) is not checked again."""
    key = (id(opts), duration, save_every, len(scene.bodies), len(scene.contacts))
    if _SIZES_CHECKED.get(key) is opts:
        return
    check_output_size(declared.samples_estimate(opts, duration, save_every), scene, declared.samples_knob)
    if len(_SIZES_CHECKED) >= MAX_CHECKED_OPTIONS:
        _SIZES_CHECKED.clear()
    _SIZES_CHECKED[key] = opts  # (held: the id names it while it is kept)


def _check_refusals(method: str, declared, scene: Scene, opts, duration: float) -> None:
    """The method's declared refusals (joints, driven motions, settings), the first that applies."""
    for refusal in declared.refusals:
        message = refusal.check(method, scene, opts, duration)
        if message is not None:
            raise InputError(message)


def _stop_conditions(stop, scene: Scene):
    """Split stop conditions into impact names (the integrators stop themselves) and callables."""
    if stop is None:
        return [], []
    items = [] if stop is None else (list(stop) if isinstance(stop, (list, tuple)) else [stop])
    names = [c.name for c in scene.contacts]
    impacts, callables = [], []
    for item in items:
        name = item.contact if isinstance(item, StopAtImpact) else item if isinstance(item, str) else None
        if name is not None:
            if name not in names:
                raise InputError(f"stop: no contact named {name!r}; contacts: {', '.join(names) or 'none'}")
            impacts.append(name)
        elif callable(item):
            callables.append(item)
        else:
            raise InputError(f"stop must be a contact name, StopAtImpact or a callable, got {item!r}")
    if len(impacts) > 1:
        raise InputError(f"stop: one impact condition at a time, got {impacts}")
    return impacts, callables


# Checked options by what they were built from (the class and each value with its type: 1 and
# True, 0.0 and -0.0 are different options): a study's thousands of runs with the same options
# check them once.
_CHECKED_OPTIONS: dict = {}
MAX_CHECKED_OPTIONS = 256


_PLAIN = (str, bool, int, type(None))  # option values that are their own key (with their type)


def _frozen(value):
    """A hashable key of an option's value and its type (dicts and lists by their items)."""
    if isinstance(value, dict):
        return dict, tuple((k, _frozen(v)) for k, v in value.items())
    if isinstance(value, (list, tuple)):
        return type(value), tuple(_frozen(v) for v in value)
    if isinstance(value, float):  # by its digits: -0.0 is not 0.0 here
        return type(value), repr(value)
    return type(value), value


def _options_key(options: dict) -> tuple:
    """_frozen(options) without the recursion for the common case of plain values (a float by
    its bits: -0.0 is not 0.0, and NaN never matches, so it is checked, and refused, every time)."""
    items = []
    for k, v in options.items():
        kind = type(v)
        if kind is float:
            items.append((k, kind, v, math.copysign(1.0, v)))
        elif kind in _PLAIN:
            items.append((k, kind, v))
        else:
            items.append((k, _frozen(v)))
    return tuple(items)


def _options(options_cls, method: str, options: dict, impact_stops: list):
    """The method's options object: checked on first use, the checked one after (kept by the
    values it was built from; no run changes its options)."""
    try:
        key = (options_cls, _options_key(options), tuple(impact_stops))
        checked = _CHECKED_OPTIONS.get(key)
    except TypeError:  # an unhashable value (an array): checked every time
        key, checked = None, None
    if checked is None:
        checked = _checked_options(options_cls, method, options, impact_stops)
        if key is not None:
            if len(_CHECKED_OPTIONS) >= MAX_CHECKED_OPTIONS:
                _CHECKED_OPTIONS.clear()
            _CHECKED_OPTIONS[key] = checked
    return checked


def _checked_options(options_cls, method: str, options: dict, impact_stops: list):
    valid = [f.name for f in dataclasses.fields(options_cls) if f.name != "stop_at_impact"]
    for key in options:
        if key not in valid:
            raise InputError(f"unknown option {quoted(key)} for method {method!r}; options: {', '.join(valid)}")
    if impact_stops:
        options = dict(options, stop_at_impact=impact_stops[0])
    try:
        return options_cls(**options)
    except InputError:
        raise
    except (TypeError, ValueError) as err:
        raise InputError(f"invalid option for method {method!r}: {err}") from None


__all__ = ["simulate", "StopAtImpact", "RunSetup", "MAX_OUTPUT_BYTES"]
