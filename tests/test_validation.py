"""nonsmooth_rod.validation: each check refuses by type and range and returns what it checked."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from nonsmooth_rod.validation import (
    Choice,
    Flag,
    InputError,
    Integer,
    Number,
    check_options,
    option,
    quoted,
    require_finite,
    require_name,
    require_state,
    require_states,
)

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


@pytest.mark.parametrize("value, fragment", [
    ("1e-3", "must be a number, got '1e-3'"),  # a string is not a number, even one that reads as one
    (True, "must be a number, got True"),  # nor is a bool
    (10**30, "integer beyond ±2^63"),  # more than the engine's integers hold
    (10**400, "integer beyond ±2^63"),
    (10**6000, "integer beyond ±2^63"),  # beyond str()'s digit limit: still one short line
    (math.nan, "must be finite"),
    ([1.0], "must be a number"),
], ids=["string", "bool", "1e30-int", "400-digit-int", "6000-digit-int", "nan", "list"])
def test_a_number_is_a_number(value, fragment):
    with pytest.raises(InputError) as err:
        require_finite("h", value)
    assert fragment in str(err.value) and len(str(err.value)) < 200


def test_checks_return_the_converted_value():
    assert type(require_finite("x", np.float32(0.5))) is float
    assert type(require_finite("x", 3)) is float
    assert Integer(1, 10)("n", 5.0) == 5 and type(Integer(1, 10)("n", 5.0)) is int
    assert Flag()("fast", np.bool_(False)) is False


@pytest.mark.parametrize("check, value, fragment", [
    (Integer(1, 10**9), True, "whole number in [1, 1000000000]"),
    (Integer(1, 10**9), 2.5, "whole number"),
    (Integer(1, 10**9), 1e30, "whole number"),
    (Integer(1, 10**9), math.nan, "whole number"),
    (Flag(), "false", "must be true or false, got 'false'"),  # "false" is truthy in Python
    (Flag(), 0, "must be true or false"),
    (Choice(("a", "b")), ["a"], "unknown x ['a']; choose from: a, b"),
    (Number(0.0, open_lo=True), 0.0, "must be positive"),
    (Number(0.0, 1.0, open_hi=True), 1.0, "must lie in [0, 1)"),
    (Number(0.0, open_lo=True, infinite=True), -math.inf, "must be finite (or inf)"),
])
def test_declared_checks_refuse_in_one_line(check, value, fragment):
    with pytest.raises(InputError) as err:
        check("x", value)
    assert fragment in str(err.value) and "\n" not in str(err.value)


def test_check_options_replaces_each_field_by_its_checked_value():
    @dataclass
    class Options:
        step: float = option(0.1, Number(0.0, open_lo=True), label="step (s)")
        count: int = option(3, Integer(1, 5))

        def __post_init__(self):
            check_options(self)

    opts = Options(step=1, count=4.0)
    assert type(opts.step) is float and type(opts.count) is int
    with pytest.raises(InputError, match=r"^step \(s\) must be positive"):
        Options(step=-1)


def test_error_messages_quote_a_short_prefix():
    assert len(quoted("x" * 20_000_000)) <= 80
    assert len(quoted(list(range(10**6)))) <= 80
    assert "\n" not in quoted("a\nb")
    with pytest.raises(InputError) as err:
        require_finite("title", "x" * 20_000_000)
    assert len(str(err.value)) < 200


@pytest.mark.parametrize("name", ["floor\n", "a\tb", "", "x" * 201, 7])
def test_names_without_control_characters(name):
    with pytest.raises(InputError):
        require_name("a contact's name", name)


@pytest.mark.parametrize("value", [["1", "2", "3"], [True, False, True], [10**30, 0, 0]])
def test_a_state_is_numbers(value):
    with pytest.raises(InputError, match="must be a sequence of 3 numbers"):
        require_state("q0", value, 3)


@pytest.mark.parametrize("bad", [[np.nan, 0.0, 0.0], np.array([0.0, np.inf, 0.0]), np.array([1e200, 0.0, 0.0]),
                                 np.array([0.0, 0.0]), np.zeros(3, dtype=np.float32) + np.nan, None, "abc"])
@pytest.mark.parametrize("which", ["q0", "v0"])
def test_both_states_at_once_refuse_what_each_alone_refuses(bad, which):
    """require_states (the driver's one call for q0 and v0, a fast path for two small float64
    arrays) refuses exactly what require_state does, naming the state; what it accepts it copies."""
    good = np.array([0.1, -0.2, 0.3])
    args = (bad, good) if which == "q0" else (good, bad)
    with pytest.raises(InputError) as alone:
        require_state(which, bad, 3)
    with pytest.raises(InputError) as together:
        require_states(*args, 3)
    assert str(together.value) == str(alone.value) and which in str(together.value)
    q0, v0 = require_states(good, good, 3)
    assert q0 is not good and v0 is not good and np.array_equal(q0, good) and np.array_equal(v0, good)
    big = np.full(3, 0.6e100)  # each within the bound, their sum over it: checked one by one, accepted
    assert np.array_equal(require_states(big, big, 3)[1], big)
