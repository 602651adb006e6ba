"""integrators/sampling.py: every method keeps one sample per save_every and tries its stop
conditions while it runs, on the scene's clock — checked on a ball dropped from rest, whose
fall Δh takes sqrt(2Δh/g) whatever the method."""
import math

import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.integrators.sampling import Thinning, save_slots

G = 9.81
HEIGHT, DROP, T0 = 2.0, 0.3, 0.5
T_FALL = math.sqrt(2 * DROP / G)  # 0.2473 s: off every sample grid below

# Each method with the spacing of the samples its stop is tried at (a step, an output sample).
METHODS = [("moreau-jean", {"h": 1e-3}, 1e-3), ("event-driven", {"output_dt": 2e-3}, 2e-3),
           ("hybrid", {"h": 1e-3}, 1e-3), ("regularized", {"output_dt": 2e-3}, 2e-3)]


def ball_over_floor():
    floor = nr.DiskOnLine(0, (0.0, 0.0), nr.Line(), 0.1, nr.ContactLaw.of(0.5, 0.5), name="floor")
    return nr.Scene([nr.RigidBody(1.0, 0.004, name="ball")], [floor], gravity=G)


def drop(method, options, **kw):
    return nr.simulate(ball_over_floor(), [0.0, HEIGHT, 0.0], [0.0, 0.0, 0.0], T0 + 1.0, method=method, t0=T0,
                       stop=lambda t, q, v: q[1] < HEIGHT - DROP, **options, **kw)


@pytest.mark.parametrize("method, options, spacing", METHODS, ids=[m[0] for m in METHODS])
def test_a_stop_ends_the_drop_at_the_first_sample_past_the_closed_form_fall_time(method, options, spacing):
    run = drop(method, options)
    assert run.status == "stopped" and run.events[-1].kind == "stop"
    t_stop = run.t[-1] - T0  # on the scene's clock: the run started at T0
    assert run.t[0] == pytest.approx(T0, abs=1e-12) and run.events[-1].t == run.t[-1]
    # the first sample at or past the fall time: within one sample spacing after it
    assert T_FALL <= t_stop <= T_FALL + spacing * (1 + 1e-9)
    assert run.q[-1, 1] < HEIGHT - DROP <= run.q[-2, 1]
    # a free fall is exact in each method (θ = ½, Runge–Kutta steps of a quadratic) to round-off
    np.testing.assert_allclose(run.q[:, 1], HEIGHT - 0.5 * G * (run.t - T0) ** 2, rtol=0, atol=1e-9 * HEIGHT)
    assert run.message == f"a stop condition held at t = {run.t[-1]:.9g} s"


@pytest.mark.parametrize("method, options, spacing", METHODS, ids=[m[0] for m in METHODS])
def test_save_every_thins_while_running_and_the_stop_is_tried_at_the_kept_samples(method, options, spacing):
    save_every = 0.05
    run = drop(method, options, save_every=save_every)
    t_stop = run.t[-1] - T0
    assert run.status == "stopped" and T_FALL <= t_stop <= T_FALL + save_every + 1e-9
    assert len(run.t) == math.floor(T_FALL / save_every) + 2  # the first, one a slot, the stop
    assert np.all(np.diff(save_slots(run.t - T0, save_every)) == 1)
    full = nr.simulate(ball_over_floor(), [0.0, HEIGHT, 0.0], [0.0, 0.0, 0.0], T0 + 0.3, method=method, t0=T0,
                       save_every=save_every, **options)
    assert full.status == "ok" and full.t[-1] == pytest.approx(T0 + 0.3, abs=1e-12)
    assert len(full.t) == 7, full.t  # the first, one a slot (0.05 … 0.25), and the last at 0.3


def test_a_stop_holding_at_the_start_ends_the_run_there():
    for method, options, _ in METHODS:
        run = nr.simulate(ball_over_floor(), [0.0, HEIGHT, 0.0], [0.0, 0.0, 0.0], 1.0, method=method,
                          stop=lambda t, q, v: True, **options)
        assert run.status == "stopped" and list(run.t) == [0.0], method


def test_thinning_keeps_the_first_sample_of_each_slot_fed_in_blocks():
    thinning = Thinning(1.0, 0.1)
    blocks = [np.array([1.0, 1.03]), np.array([1.06, 1.1, 1.12]), np.array([1.25, 1.29, 1.31])]
    kept = np.concatenate([b[thinning.keeps(b)] for b in blocks])
    np.testing.assert_array_equal(kept, [1.0, 1.1, 1.25, 1.31])
    stops = Thinning(0.0, None, [lambda t, q, v: q[0] > 1.0])
    assert stops.first_stop([0.0, 1.0, 2.0], np.array([[0.5], [1.5], [2.5]]), np.zeros((3, 1))) == 1
