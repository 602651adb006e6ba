"""What a user waits for before and around the first step (issue 16).

    python benchmarks/bench_startup.py [--quick] [--repeats 3] [--no-cold]

- first runs from an empty cache (issue 25: each ≤ 5 s wall): for the ladder (examples/scenes),
  the paper's rod (h = 1e-3, to 0.5 s) and a row of 8 balls (0.3 s), with lemke and with pgs —
  each a fresh process with its own empty NUMBA_CACHE_DIR and the default compile policy, timed
  from the process's start to the end of the call (import included). A cold run goes on
  interpreted when that is shorter than compiling (_jit); the detached compile it starts is
  killed after the measurement so it does not slow the next one;
- the compile itself: the rod with lemke in a fresh process, empty cache, NONSMOOTH_ROD_COMPILE=wait
  (what a run longer than the compile pays once, and what the background job costs);
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
ROOT = Path(__file__).resolve().parents[1]
SCENES = {  # code that sets (scene, q0, v0, t_end, h) in a fresh process
    "ladder": ("from nonsmooth_rod.scenefile import load_scene\n"
               f"sf = load_scene({str(ROOT / 'examples' / 'scenes' / 'ladder.toml')!r})\n"
               "scene, q0, v0, t_end, h = sf.scene, sf.q0, sf.v0, sf.t_end, 1e-3\n"),
    "rod": ("from nonsmooth_rod.rod.problem import RodProblem\n"
            "p = RodProblem.paper(2); q0, v0 = p.initial_state(); scene, t_end, h = p.scene(), 0.5, 1e-3\n"),
    "ball row 8": ("from nonsmooth_rod.toys.stacks import ball_row\n"
                   "scene, q0, v0 = ball_row(8); t_end, h = 0.3, 1e-3\n"),
}
COLD_RUN = ("import time; t_start = time.perf_counter()\n"
            "import nonsmooth_rod as nr\n"
            "{setup}"
            "r = nr.simulate(scene, q0, v0, t_end, method='moreau-jean', h=h, solver={solver!r})\n"
            "assert r.status == 'ok', r.message\n"
            "print(time.perf_counter() - t_start, r.stats['compiled'])\n")
ENTRY_POINTS = ("nonsmooth_rod", "nonsmooth_rod.rod.simulation", "nonsmooth_rod.cli")


def _env(**extra) -> dict:
    env = dict(os.environ, **extra)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH", "")) if p)
    return env


def _python(code: str, env: dict) -> str:
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return done.stdout


def first_runs() -> tuple[float, float]:
    """(compile, warm) seconds of the first simulate() call of a process that compiles in-process
    (empty cache, NONSMOOTH_ROD_COMPILE=wait), then of one that finds the cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = _env(NUMBA_CACHE_DIR=cache, NONSMOOTH_ROD_COMPILE="wait")
        cold = float(_python(FIRST_RUN, env).split()[-1])
        warm = float(_python(FIRST_RUN, env).split()[-1])
    return cold, warm


def cold_first_run(scene: str, solver: str) -> tuple[float, bool]:
    """(wall seconds from process start to the end of the call, ran compiled) of a scene's first
    run in a fresh process with an empty cache and the default compile policy."""
    import signal

    with tempfile.TemporaryDirectory() as cache:
        env = _env(NUMBA_CACHE_DIR=cache, NONSMOOTH_ROD_COMPILE="auto")
        start = time.perf_counter()
        out = _python(COLD_RUN.format(setup=SCENES[scene], solver=solver), env).split()
        wall = time.perf_counter() - start  # includes the interpreter's own start
        for pid_file in Path(cache).glob("*.pid"):  # the detached compile: not this benchmark's to wait for
            try:
                os.killpg(int(pid_file.read_text()), signal.SIGKILL)
            except (ProcessLookupError, PermissionError, ValueError):
                pass
    return wall, out[-1] == "True"


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
    parser.add_argument("--quick", action="store_true",
                        help="one repeat, one cold first run (ladder, lemke), no in-process compile, h = 1e-2, 1e-3")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-cold", action="store_true", help="skip the cold and warm first runs")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    yard = yardstick_s(repeats=repeats)
    print(f"yardstick (3x3 numpy.linalg.solve in a Python loop): {yard * 1e6:.2f} us")
    if not args.no_cold:
        for scene in SCENES:
            for solver in ("lemke", "pgs"):
                wall, compiled = cold_first_run(scene, solver)
                print(f"first run, empty cache: {scene:10s} {solver:5s} {wall:8.2f} s  {wall / yard:9.3g} "
                      f"yardsticks  ({'compiled' if compiled else 'interpreted'})")
                if args.quick:
                    break
            if args.quick:
                break
    if not (args.quick or args.no_cold):
        cold, warm = first_runs()
        print(f"the compile itself (rod, lemke, in-process): {cold:8.2f} s  {cold / yard:9.3g} yardsticks")
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
