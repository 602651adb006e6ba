"""Housner's rocking block: |θ̇| after/before each impact = 1 − (3/2) sin² α (α = atan(b/c))."""
import numpy as np
import pytest

from nonsmooth_rod import toys

BLOCK = toys.RockingBlock(half_width=0.1, half_height=0.3)  # α = 18.43°, ratio 0.85


def test_event_driven_ratio_at_every_impact():
    run = toys.run(BLOCK, "event-driven", 1.4)
    assert run.status == "ok", run.message
    pairs = toys.impact_rate_pairs(run)
    assert len(pairs) >= 4  # measured 4 impacts by t = 1.4 s
    before, after = BLOCK.impact_rates(len(pairs))
    for (t, w_before, w_after), wb, wa in zip(pairs, before, after):
        assert w_after / w_before == pytest.approx(BLOCK.ratio, rel=1e-9)
        assert abs(w_before) == pytest.approx(wb, rel=1e-9)
        assert abs(w_after) == pytest.approx(wa, rel=1e-9)
    # enough friction: the corners only stick or open, never slide
    assert set(run.trajectory.modes.ravel()) <= {"stick", "open"}


def test_moreau_jean_ratio_within_1e_3_and_first_order():
    """At h = 1e-4 the ratio agrees to 1e-3 (measured 5.1e-4, 5.8e-4): the impact law is
    applied with the Jacobians of the step's start, |θ̇| h ≈ 1.4e-4 rad off the impact pose, and
    the post-impact velocity is taken a step of gravity later (≈ g h b/(J_O/m) / |θ̇| ≈ 4e-4).
    Both errors are O(h): at h = 1e-3 the error is ten times larger."""
    errors = {}
    for h in (1e-3, 1e-4):
        run = toys.run(BLOCK, "moreau-jean", 0.75, h=h)
        pairs = toys.impact_rate_pairs(run)[:2]
        assert len(pairs) == 2
        errors[h] = max(abs(wa / wb - BLOCK.ratio) for _, wb, wa in pairs)
        assert set(run.trajectory.modes.ravel()) <= {"stick", "open"}
    assert errors[1e-4] < 1e-3
    assert 5 < errors[1e-3] / errors[1e-4] < 20
    # carried back to the impact time, the post-impact rate loses the step of gravity:
    run = toys.run(BLOCK, "moreau-jean", 0.75, h=1e-4)
    corrected = [abs(wa / wb - BLOCK.ratio) for _, wb, wa in toys.impact_rate_pairs(run, extrapolate=True)[:2]]
    assert max(corrected) < 3e-4  # measured 7.5e-5, 1.9e-4


def test_ratio_closed_form():
    assert BLOCK.ratio == pytest.approx(1 - 1.5 * 0.1)  # sin² α = b²/R² = 0.01/0.1
    squat = toys.RockingBlock(half_width=0.3, half_height=0.3, tilt=0.1)
    assert squat.ratio == pytest.approx(0.25)  # α = 45°
