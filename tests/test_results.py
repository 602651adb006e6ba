"""SimulationResult: a Moreau–Jean run's phases and events are located on first use (results.defer)
— the same whether read at once, after pickling (a sweep's worker sends results), or never."""
from __future__ import annotations

import copy
import dataclasses
import inspect
import math
import pickle

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.results import SimulationResult, Status


def ball_run():
    toy = toys.BouncingBall()  # dropped from 1 m: first impact at √(2 / g)
    return nr.simulate(toy.scene(), *toy.initial_state(), 0.6, h=1e-3)


def test_phases_and_events_located_on_first_use_are_the_run_s():
    run, pickled = ball_run(), pickle.loads(pickle.dumps(ball_run()))
    t1 = math.sqrt(2 * 1.0 / 9.81)
    assert [(p.mode, p.t_start, p.t_end) for p in run.phases["floor"]] == [("open", 0.0, 0.6)]  # it bounces
    impacts = [e.t for e in run.events if e.kind == "impact"]
    assert abs(impacts[0] - t1) < 1e-9 * t1  # located inside its step
    assert pickled.phases == run.phases and pickled.events == run.events
    assert copy.copy(ball_run()).events == run.events


def test_a_value_set_before_any_read_is_kept():
    run = ball_run()
    run.phases = {"floor": []}
    assert run.phases == {"floor": []} and any(e.kind == "impact" for e in run.events)


def test_the_constructor_takes_every_field_in_order_and_keeps_each_value():
    """SimulationResult.__init__ is written by hand (it fills the deferred fields' slots directly):
    it must take the dataclass's fields, in order, and give each back."""
    names = [f.name for f in dataclasses.fields(SimulationResult)]
    assert list(inspect.signature(SimulationResult).parameters) == names
    values = {name: object() for name in names}
    values["status"] = Status.STOPPED
    result = SimulationResult(**values)
    assert all(getattr(result, name) is value for name, value in values.items())
    assert SimulationResult(*values.values()) == result


def test_fields_left_out_are_each_result_s_own_empty_lists_and_dicts():
    one, two = (SimulationResult("moreau-jean", "ok", "", None, []) for _ in range(2))
    assert one.status is Status.OK and one.end_state is None and one.setup is None
    for name in ("events", "impacts", "phases", "stats", "joint_forces"):
        assert getattr(one, name) == type(getattr(one, name))() and getattr(one, name) is not getattr(two, name)
