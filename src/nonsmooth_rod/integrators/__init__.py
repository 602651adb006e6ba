"""The integrators, by method name. Each is imported only when a run asks for it.

    moreau-jean    time-stepping at velocity level, one contact problem per step (any scene)
    event-driven   smooth modes joined by located events (disks and points on lines)
    regularized    smooth friction and penalty contact integrated by a scipy ODE solver

An integrator is a class with `name`, an options dataclass, and
`run(scene, q0, v0, t_end) -> SimulationResult`; the table below also declares which contact
relations each handles, which the driver checks once before a run.
"""
from __future__ import annotations

import importlib

# method name → (module, integrator class, options class, contact relations it handles)
METHODS = {
    "moreau-jean": ("moreau_jean", "MoreauJean", "MoreauJeanOptions", ("DiskOnLine", "DiskOnDisk", "DiskOnSegment",
                                                                             "SegmentEndOnEdge")),
    "event-driven": ("event_driven", "EventDriven", "EventDrivenOptions", ("DiskOnLine",)),
    "regularized": ("regularized", "Regularized", "RegularizedOptions", ("DiskOnLine",)),
}


def supported_contacts(method: str) -> tuple[str, ...]:
    """Names of the contact relation classes a method handles."""
    return METHODS[method][3]


def integrator_classes(method: str):
    """(integrator class, options class) of a method name; KeyError if unknown."""
    module_name, cls_name, options_name, _ = METHODS[method]
    module = importlib.import_module(f"{__name__}.{module_name}")
    return getattr(module, cls_name), getattr(module, options_name)


__all__ = ["METHODS", "integrator_classes", "supported_contacts"]
