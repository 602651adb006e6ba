"""A cold compile of the Moreau–Jean loop in one process and on two cores (_compile_split).

    python benchmarks/bench_compile_split.py [--rounds 1] [--only split|one]

Each compile is `python -m nonsmooth_rod._compile_job` (what a cold run starts in the background,
and what `nonsmooth-rod compile` runs) in a fresh process with its own empty NUMBA_CACHE_DIR;
"one process" is the same with the split turned off (`_compile_split.usable_cores` → 1). Printed:
wall seconds, and CPU seconds of the job and its helper (their rusage once both have ended), with
the load average before and after (the machine is shared: say it next to the figures). The two
are alternated, `--rounds` times each.
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")
JOB = {"split": "from nonsmooth_rod import _compile_job\n",
       "one": "from nonsmooth_rod import _compile_job, _compile_split\n_compile_split.usable_cores = lambda: 1\n"}
RUN = "raise SystemExit(_compile_job.main([]))\n"


def cold_compile(mode: str) -> tuple[float, float, str]:
    """(wall s, CPU s of the job and its helper, the job's output) from an empty cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=os.pathsep.join([SRC, os.environ.get("PYTHONPATH", "")]))
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", JOB[mode] + RUN], env=env, capture_output=True, text=True,
                             check=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return wall, cpu, out.stdout.strip()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--only", choices=sorted(JOB))
    args = parser.parse_args()
    for _ in range(args.rounds):
        for mode in ([args.only] if args.only else ["one", "split"]):
            load = os.getloadavg()[0]
            wall, cpu, said = cold_compile(mode)
            print(f"{mode:6s} wall {wall:6.1f} s  cpu {cpu:6.1f} s  load {load:.1f} -> {os.getloadavg()[0]:.1f}"
                  f"  ({said})", flush=True)


if __name__ == "__main__":
    main()
