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

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

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


def _kill_and_assert_none_survive(proc, pids, seconds: float) -> None:
    """SIGKILL `proc`; none of `pids` may outlive it by more than `seconds`."""
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and any(_alive(p) for p in pids):
        time.sleep(0.1)
    survivors = [p for p in pids if _alive(p)]
    for p in survivors:  # clean up before failing
        os.kill(p, signal.SIGKILL)
    assert survivors == []


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_sigkill_of_a_sweep_leaves_no_worker():
    """The sweep's local executor (the one `sweep` opens) with both workers busy: SIGKILL the
    process that opened it, and neither worker may survive it by more than a few seconds."""
    script = textwrap.dedent("""
        import time
        from nonsmooth_rod.executors import open_executor
        with open_executor("local", 2) as (pool, workers):
            futures = [pool.submit(time.sleep, 60) for _ in range(4)]
            print("busy", flush=True)
            time.sleep(60)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], env=os.environ | {"PYTHONPATH": SRC},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "busy", proc.stderr.read()[-2000:]
    workers = _children(proc.pid)
    assert len(workers) >= 2
    _kill_and_assert_none_survive(proc, workers, seconds=5)


def _descendants(pid: int) -> list[int]:
    found, todo = [], [pid]
    while todo:
        for child in _children(todo.pop()):
            found.append(child)
            todo.append(child)
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_sigkill_of_a_dask_sweep_leaves_no_worker_or_scheduler():
    """The Dask executor's LocalCluster (worker processes) with work under way: SIGKILL the
    process that started it, and none of its processes may survive it by more than a few seconds."""
    pytest.importorskip("distributed")
    script = textwrap.dedent("""
        import time
        from nonsmooth_rod.executors import open_executor
        with open_executor("dask", 2) as (pool, workers):
            futures = [pool.submit(time.sleep, 60) for _ in range(4)]
            time.sleep(1.0)
            print("busy", flush=True)
            time.sleep(60)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], env=os.environ | {"PYTHONPATH": SRC},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "busy", proc.stderr.read()[-2000:]
    spawned = _descendants(proc.pid)
    assert len(spawned) >= 2  # the cluster's worker processes
    _kill_and_assert_none_survive(proc, spawned, seconds=10)


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
