"""Input validation: one clear sentence per mistake, raised as InputError.

Every check returns the value it checked, converted (a float, an int, a bool), so that the
caller uses what was checked and never the raw input: a string is not a number, a bool is not a
number, an integer beyond the engine's int64 is refused here rather than overflowing later.
Options dataclasses declare their checks per field (`option(default, Number(...))`) and run
them all with `check_options(self)`: one check per option, whoever builds the options.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import reprlib
from dataclasses import dataclass

import numpy as np


class InputError(ValueError):
    """Invalid user input. The message is one line, meant to be shown as is."""


_BOOLS = (bool, np.bool_)  # not numbers, whatever int(True) says
MAX_INTEGER = 2**63 - 1  # integers the engine holds (int64); a float holds larger numbers
MAX_STATE = 1e100  # |q|, |v| of an initial state: v² and k·q stay far from float64's 1.8e308
# An error message quotes at most this much of a bad value (a 20 MB string is not repeated).
QUOTE_LIMIT = 80
_QUOTER = reprlib.Repr()
_QUOTER.maxstring = _QUOTER.maxother = _QUOTER.maxlong = QUOTE_LIMIT
_QUOTER.maxlist = _QUOTER.maxtuple = _QUOTER.maxdict = _QUOTER.maxset = 6
_QUOTER.maxlevel = 3


def quoted(value) -> str:
    """A short repr of `value` for an error message: at most ~QUOTE_LIMIT characters, one line."""
    try:
        text = _QUOTER.repr(value)
    except ValueError:  # an int beyond Python's digit limit for str() (sys.get_int_max_str_digits)
        text = f"<an integer of {int(value).bit_length()} bits>" if isinstance(value, int) else "<unprintable>"
    if len(text) > QUOTE_LIMIT:
        text = text[:QUOTE_LIMIT - 3] + "..."
    return text.replace("\n", "\\n").replace("\r", "\\r")


def _real(name: str, value) -> float:
    """value as a float if it is a real number (not a bool, not a string), else InputError."""
    if type(value) is float:  # the common case, without the numbers ABCs' checks
        return value
    if isinstance(value, _BOOLS) or not isinstance(value, numbers.Real):
        raise InputError(f"{name} must be a number, got {quoted(value)}")
    if isinstance(value, numbers.Integral) and abs(int(value)) > MAX_INTEGER:
        raise InputError(f"{name} is an integer beyond ±2^63, more than the engine holds: {quoted(value)} "
                         "(write a float, e.g. 1e30)")
    try:
        return float(value)
    except OverflowError:  # a huge Fraction, say
        raise InputError(f"{name} must be finite, got {quoted(value)}") from None
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number, got {quoted(value)}") from None


def require_finite(name: str, value) -> float:
    x = _real(name, value)
    if not math.isfinite(x):
        raise InputError(f"{name} must be finite, got {quoted(value)}")
    return x


def require_positive(name: str, value) -> float:
    x = require_finite(name, value)
    if x <= 0:
        raise InputError(f"{name} must be positive, got {quoted(value)}")
    return x


def require_nonnegative(name: str, value) -> float:
    x = require_finite(name, value)
    if x < 0:
        raise InputError(f"{name} must be non-negative, got {quoted(value)}")
    return x


def require_in_range(name: str, value, lo: float, hi: float, *, open_lo=False, open_hi=False) -> float:
    x = require_finite(name, value)
    bad_lo = x <= lo if open_lo else x < lo
    bad_hi = x >= hi if open_hi else x > hi
    if bad_lo or bad_hi:
        lb = "(" if open_lo else "["
        rb = ")" if open_hi else "]"
        raise InputError(f"{name} must lie in {lb}{lo:g}, {hi:g}{rb}, got {quoted(value)}")
    return x


def require_integer(name: str, value, lo: int, hi: int) -> int:
    """A whole number in [lo, hi]: an int (not a bool), or a float with no fractional part."""
    if isinstance(value, _BOOLS):
        raise InputError(f"{name} must be a whole number in [{lo}, {hi}], got {quoted(value)}")
    if isinstance(value, numbers.Integral):
        number = int(value)
    elif isinstance(value, numbers.Real) and math.isfinite(float(value)) and float(value).is_integer():
        number = float(value)
    else:
        raise InputError(f"{name} must be a whole number in [{lo}, {hi}], got {quoted(value)}")
    if not lo <= number <= hi:
        raise InputError(f"{name} must be a whole number in [{lo}, {hi}], got {quoted(value)}")
    return int(number)


def require_flag(name: str, value) -> bool:
    """A bool option takes a bool: not the string "false" (which Python counts as true), not 0/1."""
    if isinstance(value, _BOOLS):
        return bool(value)
    raise InputError(f"{name} must be true or false, got {quoted(value)}")


def require_choice(name: str, value, choices) -> str:
    choices = tuple(choices)
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"unknown {name} {quoted(value)}; choose from: {', '.join(choices)}")
    return value


def require_name(what: str, value, max_length: int = 200) -> str:
    """A name (of a body, contact, force): a non-empty string of printable characters, no
    control characters (a newline would split a CSV header), at most max_length long."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{what} must be a non-empty string, got {quoted(value)}")
    if len(value) > max_length:
        raise InputError(f"{what} is {len(value)} characters long, more than {max_length}: {quoted(value)}")
    if not value.isprintable():
        raise InputError(f"{what} must not contain control characters (newlines, tabs, ...), got {quoted(value)}")
    return value


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
        raise InputError(f"{name} must be a whole number (an index), got {quoted(value)}")
    index = int(value)
    if index < 0:
        raise InputError(f"{name} must be non-negative, got {quoted(value)}")
    return index


def require_point(name: str, value) -> tuple[float, float]:
    """A planar point or vector: exactly two finite numbers."""
    try:
        items = list(value)
    except TypeError:
        raise InputError(f"{name} must be two numbers (x, y), got {quoted(value)}") from None
    if len(items) != 2:
        raise InputError(f"{name} must be two numbers (x, y), got {len(items)}: {quoted(value)}")
    return (require_finite(f"{name} x", items[0]), require_finite(f"{name} y", items[1]))


def require_state(name: str, value, n_dof: int):
    """An initial state q0 or v0: exactly n_dof finite numbers (x, y, θ per body), as float64."""
    if value is None:
        raise InputError(f"{name} must be a sequence of {n_dof} numbers (x, y, θ per body), got None")
    try:
        raw = np.asarray(value)
        if raw.dtype.kind not in "iuf":  # strings, bools, objects (ints beyond 64 bits): not numbers
            raise TypeError
        array = np.array(raw, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} must be a sequence of {n_dof} numbers, got {quoted(value)}") from None
    if array.shape != (n_dof,):
        raise InputError(f"{name} must hold {n_dof} numbers (x, y, θ per body), got shape {array.shape}")
    if array.size <= 32:  # a few bodies: a sum of Python floats is cheaper than a numpy reduction; it
        # bounds every |x| (NaN or inf make it fail; a sum over the bound goes on to the exact checks)
        if sum(map(abs, array.tolist())) <= MAX_STATE:
            return array
    elif np.max(np.abs(array), initial=0.0) <= MAX_STATE:  # one reduction for the common case (NaN fails it)
        return array
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be finite, got {quoted(array.tolist())}")
    if np.max(np.abs(array), initial=0.0) > MAX_STATE:
        raise InputError(f"{name} must lie within ±{MAX_STATE:g} (its squares, energies and forces must not "
                         f"overflow), got {quoted(array.tolist())}")
    return array


_FLOAT64 = np.dtype(np.float64)


def require_states(q0, v0, n_dof: int):
    """(q0, v0) checked as require_state checks each: two small float64 arrays (a call's common
    case) by one bound on both, the rest one by one."""
    if (type(q0) is np.ndarray and type(v0) is np.ndarray and q0.dtype is _FLOAT64 and v0.dtype is _FLOAT64
            and q0.shape == v0.shape == (n_dof,) and n_dof <= 32
            and sum(map(abs, q0.tolist())) + sum(map(abs, v0.tolist())) <= MAX_STATE):  # (NaN, inf fail it)
        return q0.copy(), v0.copy()
    return require_state("q0", q0, n_dof), require_state("v0", v0, n_dof)


# --- declared checks of options dataclasses ----------------------------------------------------

def _bound(x: float) -> str:
    return "inf" if x == math.inf else "-inf" if x == -math.inf else f"{x:g}"


@dataclass(frozen=True)
class Number:
    """A finite real in a range (open or closed ends); `infinite` lets +inf through (e.g. "no
    cap"), `optional` lets None through (the default decides)."""

    lo: float = -math.inf
    hi: float = math.inf
    open_lo: bool = False
    open_hi: bool = False
    infinite: bool = False
    optional: bool = False

    def __call__(self, name: str, value):
        if value is None and self.optional:
            return None
        x = _real(name, value)
        if math.isnan(x) or (math.isinf(x) and not (self.infinite and x > 0)):
            raise InputError(f"{name} must be finite{' (or inf)' if self.infinite else ''}, got {quoted(value)}")
        if (x <= self.lo if self.open_lo else x < self.lo) or (x >= self.hi if self.open_hi else x > self.hi):
            raise InputError(f"{name} must {self._range()}, got {quoted(value)}")
        return x

    def _range(self) -> str:
        if self.lo == 0.0 and self.hi == math.inf:
            return "be positive" if self.open_lo else "be non-negative"
        close = ")" if self.open_hi or self.hi == math.inf else "]"
        return f"lie in {'(' if self.open_lo else '['}{_bound(self.lo)}, {_bound(self.hi)}{close}"


@dataclass(frozen=True)
class Integer:
    lo: int
    hi: int

    def __call__(self, name: str, value) -> int:
        return require_integer(name, value, self.lo, self.hi)


@dataclass(frozen=True)
class Flag:
    def __call__(self, name: str, value) -> bool:
        return require_flag(name, value)


@dataclass(frozen=True)
class Choice:
    """One of `choices` (a tuple, or a function returning them: solvers known at run time)."""

    choices: object
    optional: bool = False

    def __call__(self, name: str, value):
        if value is None and self.optional:
            return None
        return require_choice(name, value, self.choices() if callable(self.choices) else self.choices)


@dataclass(frozen=True)
class Text:
    """Any name (an optional string without control characters), e.g. a contact to stop at."""

    def __call__(self, name: str, value):
        return None if value is None else require_name(name, value)


def option(default, check, *, label: str = "", default_factory=None):
    """A dataclass field with its check (and a longer label for messages: "h (step size)")."""
    metadata = {"check": check, "label": label}
    if default_factory is not None:
        return dataclasses.field(default_factory=default_factory, metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def check_options(options) -> None:
    """Run every field's declared check and keep the value it returns (the options' one check)."""
    for f in dataclasses.fields(options):
        check = f.metadata.get("check")
        if check is not None:
            label = f.metadata.get("label") or f.name
            object.__setattr__(options, f.name, check(label, getattr(options, f.name)))
