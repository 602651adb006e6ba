"""A step so long that a disk ends deeper than its radius in its obstacle (its centre past it) is a
run that failed, said with the contact, the step and what to do — never a result reported ok."""
import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod import toys


def test_a_step_longer_than_the_fall_fails_naming_the_contact_and_the_step():
    ball = toys.BouncingBall()  # its lowest point 1 m above the floor, radius 0.05 m
    for h in (10.0, 0.1):  # 0.1 s: from 0.4 s (gap 0.215 m, not yet predicted to close) it falls 0.44 m
        run = nr.simulate(ball.scene(), *ball.initial_state(), 20.0, h=h)
        assert run.status == "failed", (h, run.message)
        assert "floor" in run.message and "passed through" in run.message and f"{h:g} s" in run.message


def test_steps_that_catch_the_impact_never_trip_it():
    ball = toys.BouncingBall()
    for h in (3e-2, 1e-3):
        run = nr.simulate(ball.scene(), *ball.initial_state(), 2.0, h=h)
        assert run.status == "ok" and len(run.impacts) >= 2
        assert np.min(run.q[:, 1]) > 0.0  # the centre never below the floor
