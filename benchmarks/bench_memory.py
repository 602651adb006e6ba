"""Peak memory of long Moreau–Jean runs against the driver's estimate, and what a stop costs.

    python benchmarks/bench_memory.py [--quick] [--stop] [--steps 1e6 1e7]

The bouncing ball (e = 0.8, h = 1e-4 s), through the library (`nr.simulate`, with and without
`save_every`, in this process) and the CLI (`nonsmooth-rod run`, which also writes the CSV, in a
fresh process). It prints the samples kept, the estimate (`integrators.check_output_size` of the
integrator's `samples_estimate`: the bytes the run adds), the measured growth of the peak RSS
over the process before the run (library: VmHWM reset just before the run; CLI: over the peak
of the same command run for 200 steps), and their ratio. Linux only (/proc). `--stop`: CPU of a run whose stop condition holds at 5 % of
t_end against the whole run's.
"""
from __future__ import annotations

import argparse
import gc
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
H = 1e-4

def _status_kb(field: str) -> int:
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) for line in fh if line.startswith(field + ":")) * 1024


def _env():
    env = dict(os.environ, MPLBACKEND="Agg")
    # the package this process imports (the checkout's src/, or where pip installed it): a child that
    # imported another copy would compile the engine again (numba caches by source file)
    import nonsmooth_rod

    package_root = str(Path(nonsmooth_rod.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [package_root, env.get("PYTHONPATH")]))
    return env


def _ball():
    from nonsmooth_rod import toys

    ball = toys.BouncingBall(restitution=0.8)
    return ball.scene(), *ball.initial_state()


def library_case(steps: int, save_every) -> dict:
    """In this process: the peak RSS (VmHWM, reset just before through /proc/self/clear_refs)
    over the RSS before the run."""
    import nonsmooth_rod as nr
    from nonsmooth_rod.integrators import check_output_size
    from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions

    scene, q0, v0 = _ball()
    nr.simulate(scene, q0, v0, 200 * H, h=H)  # loads the compiled loop
    gc.collect()
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")  # resets VmHWM to the current RSS
    before = _status_kb("VmRSS")
    estimate = check_output_size(MoreauJean.samples_estimate(MoreauJeanOptions(h=H), steps * H, save_every), scene)
    result = nr.simulate(scene, q0, v0, steps * H, h=H, save_every=save_every)
    growth = _status_kb("VmHWM") - before
    return {"interface": "library", "steps": steps, "save_every": save_every, "samples": len(result.t),
            "estimate": estimate, "growth": growth}


def library_case_fresh(steps: int, save_every) -> dict:
    """library_case in a process of its own: in a process that ran anything large before, the
    allocator reuses what that freed and the run's growth is hidden (a 1e7-step run measured
    0.0 MB of growth after another one)."""
    import json

    here = str(Path(__file__).resolve().parent)
    # First a process that only runs the scene: if this copy of the package has not compiled that run
    # yet, it compiles and caches it there — compiling in the measured process would leave hundreds of
    # MB freed for the run to reuse, and its growth would read low (a cold CI machine: 5 MB for 20 MB).
    warm = "import sys; sys.path.insert(0, sys.argv[1]); import bench_memory; bench_memory.library_case(200, None)"
    subprocess.run([sys.executable, "-c", warm, here], env=_env(), capture_output=True, text=True, check=True)
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import bench_memory; "
            f"print(json.dumps(bench_memory.library_case({steps}, {save_every!r})))")
    done = subprocess.run([sys.executable, "-c", code, here], env=_env(), capture_output=True, text=True, check=True)
    return json.loads(done.stdout.splitlines()[-1])


def _cli_peak(steps: int, folder: str, save_every=None) -> int:
    """Peak RSS (bytes) of `nonsmooth-rod run` of the bouncing ball for `steps` steps."""
    cmd = [sys.executable, "-m", "nonsmooth_rod.cli", "run", str(ROOT / "examples/scenes/bouncing_ball.toml"),
           "--set", f"simulation.t_end={steps * H!r}", "--set", f"simulation.moreau-jean.h={H!r}",
           "--out", folder, "--no-plot", "--quiet"]
    if save_every is not None:
        cmd += ["--set", f"simulation.save_every={save_every!r}"]
    proc = subprocess.Popen(cmd, env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) not in (0, 1):
        raise RuntimeError(proc.stderr.read().decode())
    return usage.ru_maxrss * 1024


def cli_case(steps: int, save_every=None) -> dict:
    from nonsmooth_rod.integrators import check_output_size
    from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
    from nonsmooth_rod.toys import BouncingBall

    with tempfile.TemporaryDirectory() as tmp:
        _cli_peak(200, tmp)  # a first process may compile (a changed source): not the baseline
        small = _cli_peak(200, tmp)
        big = _cli_peak(steps, tmp, save_every)
    estimate = check_output_size(MoreauJean.samples_estimate(MoreauJeanOptions(h=H), steps * H, save_every),
                                 BouncingBall().scene())
    samples = steps + 1 if save_every is None else int(round(steps * H / save_every)) + 1
    return {"interface": "cli", "steps": steps, "save_every": save_every, "samples": samples, "estimate": estimate,
            "growth": big - small}


def stop_cost(steps: int) -> tuple[float, float]:
    """CPU seconds of the whole run and of the same run stopped by a condition at 5 % of t_end."""
    import nonsmooth_rod as nr

    scene, q0, v0 = _ball()
    t_end = steps * H
    nr.simulate(scene, q0, v0, 200 * H, h=H)
    # every step solved (repeat_rest off): the ball comes to rest at 4 s, and the rest of the full
    # run would cost nearly nothing — the comparison is of steps run, not of a rest repeated
    full = nr.simulate(scene, q0, v0, t_end, h=H, repeat_rest=False).cpu_time_s
    t0 = time.process_time()
    stopped = nr.simulate(scene, q0, v0, t_end, h=H, stop=lambda t, q, v: t >= 0.05 * t_end, repeat_rest=False)
    assert stopped.status == "stopped"
    return full, time.process_time() - t0


def table(rows) -> str:
    lines = ["| interface | steps | save_every (s) | samples kept | estimate (MB) | peak RSS growth (MB) | estimate / growth |",
             "|---|---|---|---|---|---|---|"]  # (the CLI's baseline: the same command for 200 steps, run twice)
    for r in rows:
        lines.append(f"| {r['interface']} | {r['steps']:.0e} | {r['save_every'] or '—'} | {r['samples']} | "
                     f"{r['estimate'] / 1e6:.1f} | {r['growth'] / 1e6:.1f} | {r['estimate'] / r['growth']:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one library case of 2e5 steps, with and without save_every")
    parser.add_argument("--stop", action="store_true", help="also the CPU of a run stopped at 5 %% of t_end")
    parser.add_argument("--steps", type=float, nargs="+", default=[1e6, 1e7])
    parser.add_argument("--cli-max-steps", type=float, default=1e7, help="CLI cases up to this many steps")
    args = parser.parse_args(argv)
    step_counts = [200_000] if args.quick else [int(s) for s in args.steps]
    print(table([]), flush=True)
    for steps in step_counts:  # each row as soon as it is measured
        cases = [lambda: library_case_fresh(steps, None), lambda: library_case_fresh(steps, 1000 * H)]
        if not args.quick and steps <= args.cli_max_steps:
            cases += [lambda: cli_case(steps), lambda: cli_case(steps, 1000 * H)]
        for case in cases:
            print(table([case()]).splitlines()[-1], flush=True)
    if args.stop:
        full, stopped = stop_cost(step_counts[-1] if args.quick else 1_000_000)
        print(f"\nstop at 5 % of t_end: {stopped:.3f} s CPU against {full:.3f} s for the whole run "
              f"({stopped / full:.1%})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
