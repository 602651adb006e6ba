"""Executors for sweeps: workers never outlive a killed sweep; the Dask executor opens and closes."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from nonsmooth_rod.executors import open_executor
from nonsmooth_rod.validation import InputError

SRC = str(Path(__file__).resolve().parents[1] / "src")


def _children(pid: int) -> list[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                out.append(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie has exited; only its exit status waits to be collected


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_sigkill_of_a_sweep_leaves_no_worker(tmp_path):
    script = textwrap.dedent(f"""
        import numpy as np
        from nonsmooth_rod.rod.problem import RodProblem
        from nonsmooth_rod.rod.regime import Grid, SweepSettings, sweep
        grid = Grid(np.linspace(0.1, 0.5, 400), np.linspace(30, 80, 50), mu_d_ratio=0.75)
        sweep(RodProblem.paper(), grid, {str(tmp_path / 'out')!r}, SweepSettings(h=1e-4), jobs=2, plot=False)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], env=os.environ | {"PYTHONPATH": SRC},
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    csv = tmp_path / "out" / "regime_map.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if csv.exists() and csv.read_text().count("\n") > 2:  # the workers are running chunks
            break
        time.sleep(0.1)
    assert proc.poll() is None, proc.stderr.read().decode()[-2000:]
    workers = _children(proc.pid)
    assert len(workers) >= 2
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 5
    while time.monotonic() < deadline and any(_alive(p) for p in workers):
        time.sleep(0.1)
    survivors = [p for p in workers if _alive(p)]
    for p in survivors:  # clean up before failing
        os.kill(p, signal.SIGKILL)
    assert survivors == []


def test_dask_local_cluster_opens_and_closes():
    pytest.importorskip("distributed")
    with open_executor("dask", jobs=1, processes=False) as (executor, workers):
        assert workers == 1
        assert executor.submit(pow, 2, 10).result(timeout=30) == 1024


def test_bad_executor_choices():
    with pytest.raises(InputError, match="--executor"):
        with open_executor("spark"):
            pass
    with pytest.raises(InputError, match="needs --executor dask"):
        with open_executor("local", 2, "tcp://127.0.0.1:1"):
            pass
    with open_executor("local", 1) as (executor, workers):
        assert executor is None and workers == 1
