"""benchmarks/bench_two_contact_solve.py --quick runs and prints every toy and solver (timings are
not asserted), and the problems it times are the toys' coupled pairs as a step makes them."""
from pathlib import Path

import numpy as np
from scripts import load_script

from nonsmooth_rod import toys

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    return load_script(ROOT / "benchmarks" / "bench_two_contact_solve.py")


def test_quick_prints_every_toy_and_solver(capsys):
    module = _bench()
    assert module.main(["--quick"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:]]
    assert [(row[0], row[1]) for row in rows] == [(name, s) for name in module.TWO_CONTACTS for s in ("lemke", "pgs")]


def test_a_flat_blocks_pair_is_statically_indeterminate():
    """Two corners of one rigid body: 4 contact rows on 3 degrees of freedom, so W = H M⁻¹ Hᵀ has
    rank 3 (both corners share one slip velocity): where such a pair sticks, its split of the
    tangential impulse is not unique (docs/solvers.md), so no closed form can rest on W > 0."""
    Ws, qs, los, his = _bench().two_contact_problems(toys.BlockOnIncline())
    assert len(Ws) > 10 and Ws.shape[1:] == (4, 4)
    for W in Ws:
        eigenvalues = np.linalg.eigvalsh(W)
        assert eigenvalues[0] <= 1e-12 * eigenvalues[-1] and eigenvalues[1] > 1e-3 * eigenvalues[-1]
        np.testing.assert_allclose(W[1], W[3], rtol=0, atol=1e-12 * np.abs(W).max())  # one slip velocity
    assert np.all(los <= his)


def test_the_toys_timed_pairs_stick_with_a_segment_of_answers():
    """The steps the benchmark times (issue 25's 200 steps of each two-contact toy) hold both
    corners stuck, and each such problem has a segment of solutions: Lemke's p plus any t along
    d = (0, 1, 0, −1) (tangential impulse moved from one corner to the other) leaves u = W p + q
    unchanged, since W d = 0, and stays in both friction intervals for an interval of t of positive
    length. So no solve that returns "the" answer where it is unique can take these steps."""
    from nonsmooth_rod.solvers.lemke import lemke_friction
    from nonsmooth_rod.solvers.problem import PlanarFrictionProblem

    d = np.array([0.0, 1.0, 0.0, -1.0])
    for name in ("BlockOnIncline", "PushedBlock", "BeltOscillator"):
        Ws, qs, los, his = _bench().two_contact_problems(getattr(toys, name)())
        assert len(Ws) > 10, name
        for W, q, lo, hi in zip(Ws, qs, los, his):
            p = lemke_friction(PlanarFrictionProblem(W, q, lo, hi)).p
            u, scale = W @ p + q, np.abs(q).max()
            assert np.abs(u).max() <= 1e-12 * scale and np.abs(W @ d).max() <= 1e-12 * np.abs(W).max(), name
            # lo_0 p_N0 ≤ p_T0 + t ≤ hi_0 p_N0 and lo_1 p_N1 ≤ p_T1 − t ≤ hi_1 p_N1
            t_low = max(lo[0] * p[0] - p[1], p[3] - hi[1] * p[2])
            t_high = min(hi[0] * p[0] - p[1], p[3] - lo[1] * p[2])
            assert t_high - t_low > 1e-3 * np.abs(p).max(), name


def test_the_toys_problems_warm_started_from_the_last_answer_take_no_pivot_and_the_same_velocities():
    """Along each two-corner toy's run, each coupled-pair problem solved by the step's Lemke
    (kernels.solve_interval) from the previous problem's answer — what the step's warm start does —
    takes the previous basis (no pivot) on all but the first, and gives the velocities u of the cold
    solve (lemke_friction), to round-off of the problem's scale: the split between the corners
    may be another end of the segment of answers, the velocities are determined."""
    from nonsmooth_rod.solvers.kernels import DEFAULT_RTOL, KERNEL_SOLVED, SOLVER_LEMKE, solve_interval
    from nonsmooth_rod.solvers.lemke import lemke_friction
    from nonsmooth_rod.solvers.problem import PlanarFrictionProblem, complementarity_residual, residual_scale

    for name in ("BlockOnIncline", "PushedBlock", "BeltOscillator"):
        Ws, qs, los, his = _bench().two_contact_problems(getattr(toys, name)())
        p, warm = np.zeros(4), 0
        for W, q, lo, hi in zip(Ws, qs, los, his):
            problem = PlanarFrictionProblem(W, q, lo, hi)
            cold = lemke_friction(problem, fallback=False)
            u = np.zeros(4)
            status, pivots, residual = solve_interval(SOLVER_LEMKE, W, q, lo, hi, p, u, 0.0, 0)
            scale = residual_scale(problem, p, u)
            assert status == KERNEL_SOLVED and complementarity_residual(problem, p) <= DEFAULT_RTOL * scale
            np.testing.assert_allclose(u, cold.u, rtol=0, atol=1e-12 * scale, err_msg=name)
            warm += pivots == 0 < cold.iterations
        assert warm == len(Ws) - 1, name
