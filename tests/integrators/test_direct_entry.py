"""The compiled loop's entry called without numba's overload search (integrators/direct_entry.py):
only for objects an earlier call passed to the dispatcher's one overload, and a run that takes it
is the run through the dispatcher bit for bit."""
from types import SimpleNamespace

import numpy as np
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.integrators import moreau_jean
from nonsmooth_rod.integrators.direct_entry import MAX_KNOWN_BYTES, DirectEntry

from test_scene_plans import assert_identical, ball_scene, no_kept_plans, run  # noqa: F401  (fixture)


class FakeDispatcher:
    """Stands for a numba dispatcher: its calls and its overloads' entry points' calls counted."""

    def __init__(self, overloads: int = 1):
        self.calls = 0
        self.entry_calls = 0
        self.overloads = {f"sig{i}": SimpleNamespace(entry_point=self._entry) for i in range(overloads)}

    def __call__(self, *args):
        self.calls += 1
        return 0

    def _entry(self, *args):
        self.entry_calls += 1
        return 0


def small(n=3, rows=4):
    return (np.zeros(n), np.zeros(n), np.zeros((n, 6))), (np.zeros(n), np.zeros(n), np.zeros((n, 6))), \
        (np.zeros((rows, 3)), np.zeros(rows), np.zeros((rows, n)))


def call(direct, kernels, model, work, out):
    return direct.run_steps(kernels, 0, 1, np.zeros(2), np.zeros(2, dtype=np.int64), model, work, out, np.zeros(0))


def test_known_arguments_go_through_the_entry_point_new_ones_through_the_dispatcher():
    direct, dispatcher = DirectEntry(), FakeDispatcher()
    kernels = SimpleNamespace(run_steps=dispatcher)
    model, work, out = small()
    call(direct, kernels, model, work, out)
    assert (dispatcher.calls, dispatcher.entry_calls) == (1, 0)
    call(direct, kernels, model, work, out)
    call(direct, kernels, model, work, out)
    assert (dispatcher.calls, dispatcher.entry_calls) == (1, 2)
    other_out = small()[2]  # new records (a widened window, another lent set): searched again
    call(direct, kernels, model, work, other_out)
    assert (dispatcher.calls, dispatcher.entry_calls) == (2, 2)


def test_several_overloads_or_none_always_go_through_the_dispatcher():
    for dispatcher in (FakeDispatcher(overloads=2), SimpleNamespace(calls=0)):
        if isinstance(dispatcher, SimpleNamespace):  # the interpreted twin: a plain function
            def plain(*args, counted=dispatcher):
                counted.calls += 1
                return 0
            kernels = SimpleNamespace(run_steps=plain)
        else:
            kernels = SimpleNamespace(run_steps=dispatcher)
        direct, (model, work, out) = DirectEntry(), small()
        for _ in range(3):
            call(direct, kernels, model, work, out)
        assert dispatcher.calls == 3


def test_large_arguments_are_not_held():
    direct, dispatcher = DirectEntry(), FakeDispatcher()
    kernels = SimpleNamespace(run_steps=dispatcher)
    model, work, _ = small()
    rows = MAX_KNOWN_BYTES // (3 * 8) + 1  # a long run's records
    out = (np.zeros((rows, 3)), np.zeros(rows), np.zeros((rows, 3)))
    call(direct, kernels, model, work, out)
    call(direct, kernels, model, work, out)
    assert (dispatcher.calls, dispatcher.entry_calls) == (2, 0)
    assert not direct._state[2]


@pytest.mark.skipif(not _jit.ENABLED, reason="the compiled loop (numba) is off")
def test_a_run_through_the_entry_point_is_the_run_through_the_dispatcher(monkeypatch):
    scene = ball_scene()
    runs = [run(scene, repeat_rest=False) for _ in range(4)]  # lent sets come back from the third
    counted = {"entry": 0}
    dispatcher, entry, known = moreau_jean._DIRECT._state
    assert entry is not None  # the compiled loop has one overload

    def counting(*args):
        counted["entry"] += 1
        return entry(*args)

    monkeypatch.setattr(moreau_jean._DIRECT, "_state", (dispatcher, counting, known))
    again = run(scene, repeat_rest=False)
    assert counted["entry"] == 1
    monkeypatch.setattr(moreau_jean, "_DIRECT", DirectEntry())  # through the dispatcher
    fresh = run(ball_scene(), repeat_rest=False)
    for got in (again, *runs):
        assert_identical(got, fresh)
