"""Moreau–Jean's discrete energy balance (docs/friction.md, "Energy"), checked on random scenes by
benchmarks/bench_energy.py: its quick mode, the θ-method's own term, and the order in h of what
the start-of-step Jacobian adds."""
from pathlib import Path

import numpy as np
import pytest

import nonsmooth_rod as nr
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_energy.py")


def _scene(index, seed=28):
    """The index-th random scene of bench_energy's generator."""
    bench, rng = _bench(), np.random.default_rng(seed)
    for _ in range(index):
        bench.random_scene(rng)
    return bench, bench.random_scene(rng)


def test_quick_run_meets_the_balance_and_the_bound_on_every_step(capsys):
    assert _bench().main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "ΔE ≤ start work⁺: yes" in out
    gaining = int(out.split("scenes gaining energy in some step (> 1e-12 of the scale): ")[1].split(";")[0])
    assert gaining > 0  # the bound is not vacuous: some scenes do gain energy in some step


@pytest.mark.parametrize("theta", [0.5, 0.75, 1.0])
def test_the_balance_is_exact_and_theta_above_half_adds_its_own_dissipation(theta):
    """ΔE = ½ pᵀH(q_k)(v_k + v_{k+1}) − (θ − ½) h fᵀ(v_{k+1} − v_k) for gravity f, to round-off."""
    bench, (scene, q0, v0) = _scene(2)
    h = 2e-3
    result = nr.simulate(scene, q0, v0, 0.4, h=h, theta=theta, solver="lemke")
    assert result.status == "ok"
    d_energy, start, end, _ = bench.energy_balance(scene, result)
    f = scene.force(0.0, q0, v0)
    theta_term = -(theta - 0.5) * h * (np.diff(result.v, axis=0) @ f)
    scale = max(abs(scene.energy(q0, v0)), scene.kinetic_energy(v0))
    assert np.max(np.abs(d_energy - start - end - theta_term)) <= bench.BALANCE_TOL * scale
    if theta > 0.5:
        assert np.max(np.abs(theta_term)) > 1e3 * bench.BALANCE_TOL * scale  # the term is really there


def test_the_gain_is_second_order_per_step_and_first_order_over_a_run():
    """A rod leaning on a ball (scene 2): its largest gain in one step falls 4× when h halves,
    its total gain over 0.8 s 2× — the O(h²) start work of a persistent contact."""
    bench, (scene, q0, v0) = _scene(2)
    worst, total = [], []
    for h in (4e-3, 2e-3, 1e-3):
        result = nr.simulate(scene, q0, v0, 0.8, h=h, solver="lemke")
        d_energy = bench.energy_balance(scene, result)[0]
        worst.append(np.max(d_energy))
        total.append(np.sum(np.maximum(d_energy, 0.0)))
    assert worst[0] > 1e-8  # measured 5.3e-7 J
    assert all(3.0 < a / b < 5.0 for a, b in zip(worst, worst[1:])), worst
    assert all(1.5 < a / b < 2.5 for a, b in zip(total, total[1:])), total
