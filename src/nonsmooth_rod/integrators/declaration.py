"""What an integrator declares about itself, for the driver's one check before a run.

Each integrator class carries a `Declaration` (its `declares` attribute, next to its code): its
options dataclass, the contact relations it runs, what else it refuses (joints, driven motions,
a setting that does not go with the scene…), each with its one-line refusal, how many samples a
run keeps (the one memory check) and how it checks an end state to resume from. Every `run`
keeps the scene's clock, thins and stops itself (integrators/sampling.py). The driver (driver.py) reads only this: it never asks which method it is running.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Refusal:
    """Something a method does not run. `finds(scene, options, duration)` returns None, or the
    fields of `message` (a dict) naming what it found; the message is one line, formatted with
    those fields and `method`."""

    finds: Callable
    message: str

    def check(self, method: str, scene, options, duration: float) -> str | None:
        found = self.finds(scene, options, duration)
        return None if found is None else self.message.format(method=method, **found)


@dataclass(frozen=True)
class Declaration:
    """An integrator's declaration (its class's `declares`).

    options: the options dataclass (the driver builds it from the caller's keywords);
    contacts: the names of the contact relation classes it runs (any other is refused by name);
    refusals: the rest it does not run (`Refusal`s, tried in order);
    samples_estimate(options, duration, save_every): the samples a run keeps, counting what it
    holds while it runs (the driver's memory check); samples_knob: what keeps fewer;
    resumes: how it checks an `end_state` to continue from (None: it restarts from (q, v) alone);
    compiles(options): True when a run with these options would run numba-compiled code (the
    driver then says once if numba is missing; None: never).
    """

    options: type
    contacts: tuple
    samples_estimate: Callable
    samples_knob: str
    refusals: tuple = ()
    resumes: Callable | None = None
    compiles: Callable | None = None


def first_item(items: Callable, field: str = "item") -> Callable:
    """A refusal's finder: the fields {field: the first of `items(scene)`} (names, as the message
    says them), or None when there is none."""
    def finds(scene, options=None, duration=None) -> dict | None:
        found = next(iter(items(scene)), None)
        return None if found is None else {field: found}
    return finds


# The scene's first joint; its first driven obstacle or body.
first_joint = first_item(lambda scene: (f"joint {joint.name!r}" for joint in scene.joints))
first_driven = first_item(lambda scene: scene.driven_things())


NO_JOINTS = Refusal(first_joint, "method {method!r} does not handle joints ({item}); use moreau-jean")
NO_DRIVEN = Refusal(first_driven, "method {method!r} does not handle driven obstacles or bodies ({item} moves by a "
                                  "prescribed motion): it lacks their time-dependent gap and velocity; use moreau-jean")

# A max_step asking scipy for more steps than this is refused (about a minute of stepping).
MAX_CAPPED_STEPS = 10**6


def _capped_steps(scene, options, duration: float) -> dict | None:
    cap = options.max_step
    if duration / cap > MAX_CAPPED_STEPS:
        return {"cap": cap, "duration": duration, "least": duration / MAX_CAPPED_STEPS}
    return None


# The ODE methods' step cap: one that makes the run a hang (more than MAX_CAPPED_STEPS steps of
# scipy's integrators, each tens of microseconds) is refused.
STEP_CAP = Refusal(_capped_steps, f"max_step = {{cap:g}} s over a run of {{duration:g}} s asks for more than "
                                  f"{MAX_CAPPED_STEPS:.0e} ODE steps: use max_step ≥ {{least:.3g}} s")


__all__ = ["Declaration", "Refusal", "NO_JOINTS", "NO_DRIVEN", "STEP_CAP", "MAX_CAPPED_STEPS",
           "first_item", "first_joint", "first_driven"]
