"""The integrators, by method name. Each is imported only when a run asks for it.

    moreau-jean    time-stepping at velocity level, one contact problem per step (any scene)
    event-driven   smooth modes joined by located events (bodies' disks, points and polygons
                   against fixed lines and segments)
    regularized    smooth friction and penalty contact integrated by a scipy ODE solver

An integrator is a class with `name`, an options dataclass, and
`run(scene, q0, v0, t_end) -> SimulationResult`; the table below also declares which contact
relations each handles, which the driver checks once before a run.
"""
from __future__ import annotations

import importlib
import math

from ..validation import InputError

# The one memory limit of every method: a run whose kept samples would need more than this
# (bytes, check_output_size's estimate) is refused before it allocates anything.
MAX_OUTPUT_BYTES = 4 * 2**30

# method name → (module, integrator class, options class, contact relations it handles)
METHODS = {
    "moreau-jean": ("moreau_jean", "MoreauJean", "MoreauJeanOptions", ("DiskOnLine", "DiskOnDisk", "DiskOnSegment",
                                                                             "SegmentEndOnEdge", "VertexOnEdge")),
    "event-driven": ("event_driven", "EventDriven", "EventDrivenOptions", ("DiskOnLine", "DiskOnSegment",
                                                                             "SegmentEndOnEdge", "VertexOnEdge")),
    "regularized": ("regularized", "Regularized", "RegularizedOptions", ("DiskOnLine",)),
}

# The methods that run driven obstacles and bodies (model/motion.py). The event-driven reference
# would need each driven contact's gap, velocity and acceleration as functions of time in its
# modes' ODEs and event functions, the regularized method the obstacle's velocity in its penalty
# and friction laws: neither has them yet, and refuses such a scene by name.
DRIVEN_METHODS = ("moreau-jean",)


def check_driven(method: str, scene) -> None:
    """Refuse, in one line, a driven obstacle or body for a method that does not move them."""
    driven = scene.driven_things()
    if driven and method not in DRIVEN_METHODS:
        raise InputError(f"method {method!r} does not handle driven obstacles or bodies ({driven[0]} moves by a "
                         f"prescribed motion): it lacks their time-dependent gap and velocity; use "
                         f"{', '.join(DRIVEN_METHODS)}")
# The methods that take bilateral joints (model/joints.py); the driver refuses a jointed scene for
# the others, naming a joint.
HANDLES_JOINTS = ("moreau-jean",)


def supported_contacts(method: str) -> tuple[str, ...]:
    """Names of the contact relation classes a method handles."""
    return METHODS[method][3]


def integrator_classes(method: str):
    """(integrator class, options class) of a method name; KeyError if unknown."""
    module_name, cls_name, options_name, _ = METHODS[method]
    module = importlib.import_module(f"{__name__}.{module_name}")
    return getattr(module, cls_name), getattr(module, options_name)


def sample_bytes(n_dof: int, n_contacts: int) -> int:
    """Bytes one kept sample holds in a result: t; q, v, a (n_dof floats each); N, T (floats)
    and the mode (a reference to a shared word, plus its one-byte code while it is built)."""
    return 8 + 24 * n_dof + 25 * n_contacts


def check_output_size(samples: float, scene, knob: str = "save_every or a shorter t_end") -> float:
    """Refuse a run whose `samples` kept samples cannot fit the limit; returns the bytes they need.
    Each integrator's `samples_estimate(options, duration, save_every)` says how many it keeps,
    its `SAMPLES_KNOB` what lowers it."""
    needed = samples * sample_bytes(scene.n_dof, len(scene.contacts))
    if not math.isfinite(needed) or needed > MAX_OUTPUT_BYTES:
        raise InputError(f"the run would keep {samples:.3g} samples ({needed / 2**30:.3g} GiB), over the "
                         f"{MAX_OUTPUT_BYTES / 2**30:g} GiB limit: use {knob}")
    return needed


__all__ = ["METHODS", "DRIVEN_METHODS", "check_driven", "HANDLES_JOINTS", "MAX_OUTPUT_BYTES", "check_output_size",
           "integrator_classes", "sample_bytes",
           "supported_contacts"]
