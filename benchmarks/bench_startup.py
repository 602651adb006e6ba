"""What a user waits for before and around the first step (issue 16).

    python benchmarks/bench_startup.py [--quick] [--repeats 3] [--no-cold]

- cold first run: a fresh process with an empty NUMBA_CACHE_DIR running
  `nr.simulate(rod scene, method="moreau-jean", h=1e-3)` (the time of that call, measured inside
  the process: numba compiles the engine during it); issue 16's target is ≤ 5 s on an idle
  2-core machine, ≤ 1.6e6 yardsticks;
- warm first run: the same in a second fresh process that finds the cache (cache hit);
- import time of `nonsmooth_rod` and of the entry points `nonsmooth_rod.rod.simulation` and
  `nonsmooth_rod.cli` (each in a fresh process, `-X importtime`-free wall time of the import);
- whole call vs integrator: `nonsmooth_rod.rod.simulation.simulate(method="moreau-jean", h)`
  (CPU time of the call) against the integrator's own CPU time (`result.cpu_time_s`), for
  h = 1e-2, 1e-3, 1e-4 (target: whole/integrator ≤ 1.5 at h = 1e-3).

Every time is also given in yardsticks (one 3×3 numpy.linalg.solve in a Python loop, timed in
the same run); medians of the repeats. --quick: one repeat, no cold compile, h = 1e-2 and 1e-3.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for the yardstick
from yardstick import yardstick_us  # noqa: E402  (benchmarks/yardstick.py)

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
FIRST_RUN = ("import time, nonsmooth_rod as nr\n"
             "from nonsmooth_rod.rod.problem import RodProblem\n"
             "p = RodProblem.paper(2); q0, v0 = p.initial_state()\n"
             "t0 = time.perf_counter()\n"
             "r = nr.simulate(p.scene(), q0, v0, 0.05, method='moreau-jean', h=1e-3)\n"
             "assert r.status == 'ok' and r.stats['compiled'], (r.status, r.stats)\n"
             "print(time.perf_counter() - t0)\n")
ENTRY_POINTS = ("nonsmooth_rod", "nonsmooth_rod.rod.simulation", "nonsmooth_rod.cli")


def _env(**extra) -> dict:
    env = dict(os.environ, **extra)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH", "")) if p)
    return env


def _python(code: str, env: dict) -> str:
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return done.stdout


def first_runs() -> tuple[float, float]:
    """(cold, warm) seconds of the first simulate() call of a process: empty cache, then a hit."""
    with tempfile.TemporaryDirectory() as cache:
        env = _env(NUMBA_CACHE_DIR=cache)
        cold = float(_python(FIRST_RUN, env).split()[-1])
        warm = float(_python(FIRST_RUN, env).split()[-1])
    return cold, warm


def import_seconds(module: str, repeats: int) -> float:
    """Median wall time of `import module` in a fresh process."""
    code = f"import time; t0 = time.perf_counter(); import {module}; print(time.perf_counter() - t0)"
    return statistics.median(float(_python(code, _env()).split()[-1]) for _ in range(repeats))


def whole_vs_integrator(h: float, repeats: int) -> tuple[float, float]:
    """(whole call, integrator) CPU seconds of the rod's Moreau–Jean run to ball B's impact."""
    from nonsmooth_rod.rod.simulation import simulate

    simulate(method="moreau-jean", h=h)  # compile / load the engine first
    whole, integrator = [], []
    for _ in range(repeats):
        t0 = time.process_time()
        run = simulate(method="moreau-jean", h=h)
        whole.append(time.process_time() - t0)
        integrator.append(run.result.cpu_time_s)
    return statistics.median(whole), statistics.median(integrator)


def yardstick_s(n: int = 20000, repeats: int = 3) -> float:
    """The yardstick in seconds."""
    return yardstick_us(n, repeats) * 1e-6


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one repeat, no cold compile, h = 1e-2, 1e-3")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-cold", action="store_true", help="skip the cold and warm first runs")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    yard = yardstick_s(repeats=repeats)
    print(f"yardstick (3x3 numpy.linalg.solve in a Python loop): {yard * 1e6:.2f} us")
    if not (args.quick or args.no_cold):
        cold, warm = first_runs()
        print(f"first run, empty numba cache: {cold:8.2f} s  {cold / yard:9.3g} yardsticks")
        print(f"first run, cache hit:         {warm:8.2f} s  {warm / yard:9.3g} yardsticks")
    for module in ENTRY_POINTS:
        seconds = import_seconds(module, repeats)
        print(f"import {module:29s} {seconds:8.3f} s  {seconds / yard:9.3g} yardsticks")
    for h in ((1e-2, 1e-3) if args.quick else (1e-2, 1e-3, 1e-4)):
        whole, integrator = whole_vs_integrator(h, repeats)
        print(f"rod h={h:g}: whole call {whole * 1e3:8.2f} ms ({whole / yard:8.3g} yd), integrator "
              f"{integrator * 1e3:8.2f} ms ({integrator / yard:8.3g} yd), ratio {whole / integrator:5.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
