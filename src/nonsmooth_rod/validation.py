"""Input validation: one clear sentence per mistake, raised as InputError."""
from __future__ import annotations

import math


class InputError(ValueError):
    """Invalid user input. The message is one line, meant to be shown as is."""


def require_finite(name: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise InputError(f"{name} must be finite, got {value!r}")
    return x


def require_positive(name: str, value) -> float:
    x = require_finite(name, value)
    if x <= 0:
        raise InputError(f"{name} must be positive, got {value!r}")
    return x


def require_nonnegative(name: str, value) -> float:
    x = require_finite(name, value)
    if x < 0:
        raise InputError(f"{name} must be non-negative, got {value!r}")
    return x


def require_in_range(name: str, value, lo: float, hi: float, *, open_lo=False, open_hi=False) -> float:
    x = require_finite(name, value)
    bad_lo = x <= lo if open_lo else x < lo
    bad_hi = x >= hi if open_hi else x > hi
    if bad_lo or bad_hi:
        lb = "(" if open_lo else "["
        rb = ")" if open_hi else "]"
        raise InputError(f"{name} must lie in {lb}{lo:g}, {hi:g}{rb}, got {value!r}")
    return x


def require_friction_pair(mu_s, mu_d) -> tuple[float, float]:
    mu_s = require_nonnegative("mu_s (static friction coefficient)", mu_s)
    mu_d = require_nonnegative("mu_d (dynamic friction coefficient)", mu_d)
    if mu_d > mu_s:
        raise InputError(
            f"mu_d = {mu_d:g} exceeds mu_s = {mu_s:g}: the dynamic (sliding) friction coefficient "
            "must not exceed the static one"
        )
    return mu_s, mu_d


def require_index(name: str, value) -> int:
    """A non-negative whole number used as an index (a body number): not 1.5, not True."""
    if isinstance(value, bool) or not isinstance(value, (int,)) and not (
            hasattr(value, "__index__") and not isinstance(value, float)):
        raise InputError(f"{name} must be a whole number (an index), got {value!r}")
    index = int(value)
    if index < 0:
        raise InputError(f"{name} must be non-negative, got {value!r}")
    return index


def require_point(name: str, value) -> tuple[float, float]:
    """A planar point or vector: exactly two finite numbers."""
    try:
        items = list(value)
    except TypeError:
        raise InputError(f"{name} must be two numbers (x, y), got {value!r}") from None
    if len(items) != 2:
        raise InputError(f"{name} must be two numbers (x, y), got {len(items)}: {value!r}")
    return (require_finite(f"{name} x", items[0]), require_finite(f"{name} y", items[1]))


def require_state(name: str, value, n_dof: int):
    """An initial state q0 or v0: exactly n_dof finite numbers (x, y, θ per body), as float64."""
    import numpy as np

    if value is None:
        raise InputError(f"{name} must be a sequence of {n_dof} numbers (x, y, θ per body), got None")
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a sequence of {n_dof} numbers, got {value!r}") from None
    if array.shape != (n_dof,):
        raise InputError(f"{name} must hold {n_dof} numbers (x, y, θ per body), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be finite, got {array.tolist()!r}")
    return array
