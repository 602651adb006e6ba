"""What fixed-step Moreau–Jean's stick decisions by the smooth phase (integrators/
stick_decisions.py) cost: CPU time of whole `nr.simulate` calls per step, with the decisions and
without them (the step's law alone, as before them), alternated in one process, as ratios to the
yardstick measured beside each (benchmarks/yardstick.py); medians of the repeats.

    python benchmarks/bench_stick_decisions.py [--repeats 7]

Scenes: the paper's rod (case 2) at h = 1e-4 (issue 25's per-step target case; it breaks away
once), the rod at μs = max T/N + 1e-6, h = 1e-3, to ball B's impact (a break-away taken back,
held through the peak and released: one prediction), the belt oscillator over 5 s at h = 1e-3
(a break-away every cycle), and a 50-step run of a block on an incline (the fixed cost of a call).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from yardstick import yardstick_us  # noqa: E402

import nonsmooth_rod as nr  # noqa: E402
from nonsmooth_rod import toys  # noqa: E402
from nonsmooth_rod.integrators import moreau_jean  # noqa: E402
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis  # noqa: E402
from nonsmooth_rod.rod.problem import RodProblem  # noqa: E402


def cases():
    rod = RodProblem.paper(2)
    yield "rod (paper case 2), h = 1e-4, 0.3 s", rod.scene(), *rod.initial_state(), 1e-4, 0.3
    peak = rolling_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.2)).T_over_N_max
    grazing = RodProblem.paper(None, mu_s=peak + 1e-6, mu_d=0.2)
    yield "rod at μs = max T/N + 1e-6, h = 1e-3", grazing.scene(), *grazing.initial_state(), 1e-3, 0.38
    belt = toys.BeltOscillator()
    yield "belt oscillator, h = 1e-3, 5 s", belt.scene(), *belt.initial_state(), 1e-3, 5.0
    block = toys.BlockOnIncline()
    yield "block on incline, 50 steps", block.scene(), *block.initial_state(), 1e-3, 0.05


def per_step(scene, q0, v0, h, t_end, decisions: bool) -> tuple[float, dict]:
    saved = moreau_jean.stick_decisions
    if not decisions:
        moreau_jean.stick_decisions = lambda *args: None
    try:
        started = time.process_time()
        run = nr.simulate(scene, q0, v0, t_end, "moreau-jean", h=h)
        return (time.process_time() - started) / run.steps * 1e6, run.stats
    finally:
        moreau_jean.stick_decisions = saved


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args(argv)
    print("| scene | without (yardsticks a step) | with | with / without | predictions a run |\n|---|---|---|---|---|")
    for name, scene, q0, v0, h, t_end in cases():
        per_step(scene, q0, v0, h, t_end, True)  # warm: compile or load, imports
        ratios = {True: [], False: []}
        for _ in range(args.repeats):
            for on in (False, True):
                yard = yardstick_us(n=5000, repeats=3)
                us, stats = per_step(scene, q0, v0, h, t_end, on)
                ratios[on].append(us / yard)
        without, with_ = statistics.median(ratios[False]), statistics.median(ratios[True])
        print(f"| {name} | {without:.3f} | {with_:.3f} | {with_ / without:.3f} | {stats['stick_predictions']} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
