"""The integrators, by method name. Each is imported only when a run asks for it.

    moreau-jean    time-stepping at velocity level, one contact problem per step (any scene)
    event-driven   smooth modes joined by located events (bodies' disks, points and polygons
                   against fixed lines and segments)
    regularized    smooth friction and penalty contact integrated by a scipy ODE solver
    hybrid         fixed explicit Runge–Kutta steps in each smooth mode, the event-driven events

An integrator is a class with `name`, `declares` (integrators/declaration.py: its options
dataclass, the contact relations it runs, what else it refuses and why, how many samples a run
keeps) and `run(scene, q0, v0, t_end) -> SimulationResult`. The driver checks a run once against
the declaration, and the integrator trusts what it is given.
"""
from __future__ import annotations

import importlib
import math

from ..validation import InputError

# The one memory limit of every method: a run whose kept samples would need more than this
# (bytes, check_output_size's estimate) is refused before it allocates anything.
MAX_OUTPUT_BYTES = 4 * 2**30

# method name → (module, integrator class)
METHODS = {
    "moreau-jean": ("moreau_jean", "MoreauJean"),
    "event-driven": ("event_driven", "EventDriven"),
    "regularized": ("regularized", "Regularized"),
    "hybrid": ("hybrid", "Hybrid"),
}
_CLASSES: dict = {}  # method name → its integrator class, imported once per process


def integrator_class(method: str):
    """The integrator class of a method name (its module imported on first use); KeyError if unknown."""
    cls = _CLASSES.get(method)
    if cls is None:
        module_name, cls_name = METHODS[method]
        cls = _CLASSES[method] = getattr(importlib.import_module(f"{__name__}.{module_name}"), cls_name)
    return cls


def integrator_classes(method: str):
    """(integrator class, options class) of a method name; KeyError if unknown."""
    cls = integrator_class(method)
    return cls, cls.declares.options


def supported_contacts(method: str) -> tuple[str, ...]:
    """Names of the contact relation classes a method handles (its declaration's)."""
    return integrator_class(method).declares.contacts


def sample_bytes(n_dof: int, n_contacts: int) -> int:
    """Bytes one kept sample holds in a result: t; q, v, a (n_dof floats each); N, T (floats)
    and the mode (a reference to a shared word, plus its one-byte code while it is built)."""
    return 8 + 24 * n_dof + 25 * n_contacts


def check_output_size(samples: float, scene, knob: str = "save_every or a shorter t_end") -> float:
    """Refuse a run whose `samples` kept samples cannot fit the limit; returns the bytes they need.
    Each integrator's declaration says how many it keeps (`samples_estimate(options, duration,
    save_every)`) and what lowers it (`samples_knob`)."""
    needed = samples * sample_bytes(scene.n_dof, len(scene.contacts))
    if not math.isfinite(needed) or needed > MAX_OUTPUT_BYTES:
        raise InputError(f"the run would keep {samples:.3g} samples ({needed / 2**30:.3g} GiB), over the "
                         f"{MAX_OUTPUT_BYTES / 2**30:g} GiB limit: use {knob}")
    return needed


__all__ = ["METHODS", "MAX_OUTPUT_BYTES", "check_output_size", "integrator_class", "integrator_classes",
           "sample_bytes", "supported_contacts"]
