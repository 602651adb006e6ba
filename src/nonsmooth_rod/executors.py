"""Where a sweep's chunks run: in this process, a local process pool, or a Dask cluster.

Anything with the `concurrent.futures` interface (`submit` returning futures that
`concurrent.futures.wait` understands) works: a `ProcessPoolExecutor`, loky's executor, a Dask
client's `get_executor()`. `open_executor` builds the two the CLI offers:

* ``local``: a `ProcessPoolExecutor` whose workers exit when the process that started them
  dies — even by SIGKILL, which runs no clean-up: each worker polls its parent's pid (a child
  is re-parented when its parent dies), so no orphan keeps sleeping on the task queue.
* ``dask``: a `dask.distributed` client on `scheduler` (an address), or on a LocalCluster
  started here and closed at the end. Its worker processes are started by nannies living in
  this process and watch it through a pipe (distributed's own mechanism), so they too end with
  it. Dask is the optional extra ``dist``.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures.process import BrokenProcessPool

from .io import RunAborted
from .validation import InputError

EXECUTORS = ("local", "dask")
PARENT_POLL_S = 0.25  # how often a local worker checks that its parent is alive


class WorkerLost(RunAborted):
    """A worker process of the local pool died (killed, out of memory): the pool is unusable."""


def _watch_parent(parent_pid: int) -> None:
    while True:
        time.sleep(PARENT_POLL_S)
        if os.getppid() != parent_pid:
            os._exit(70)  # the sweep is gone: nothing to report to, no clean-up owed


def _init_local_worker(parent_pid: int, initializer=None, initargs=()) -> None:
    # Ctrl-C goes to the whole process group; the parent handles it and cancels the pool.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="parent-watch").start()
    if initializer is not None:
        initializer(*initargs)


def local_executor(jobs: int, initializer=None, initargs=()):
    """A process pool of `jobs` workers that die with this process. Forked where the platform
    allows it, so the workers inherit the already loaded (compiled) engine."""
    from concurrent.futures import ProcessPoolExecutor

    if jobs < 1:
        raise InputError(f"jobs must be at least 1, got {jobs}")
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else None)
    return ProcessPoolExecutor(max_workers=jobs, mp_context=context, initializer=_init_local_worker,
                               initargs=(os.getpid(), initializer, initargs))


def _dask_client(scheduler: str | None, jobs: int, processes: bool):
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError("--executor dask needs dask.distributed: pip install 'nonsmooth-rod[dist]'") from None
    import logging

    if scheduler:
        try:
            return Client(scheduler, timeout="10s"), None
        except (OSError, TimeoutError) as err:
            raise InputError(f"--scheduler {scheduler!r}: cannot connect ({err})") from None
    cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=processes, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


@contextlib.contextmanager
def open_executor(kind: str = "local", jobs: int = 2, scheduler: str | None = None, *, processes: bool = True):
    """Yield (executor or None for in-process, number of workers); close what was opened here.

    `processes=False` runs a LocalCluster's workers as threads (tests, tiny sweeps)."""
    if kind not in EXECUTORS:
        raise InputError(f"--executor must be one of {', '.join(EXECUTORS)}, got {kind!r}")
    if scheduler and kind != "dask":
        raise InputError("--scheduler needs --executor dask")
    if kind == "local":
        if jobs == 1:
            yield None, 1
            return
        pool = local_executor(jobs)
        # Start (fork) the workers now, before the caller starts threads (a progress bar):
        # forking while another thread holds a lock can deadlock the child.
        pool.submit(os.getpid).result()
        try:
            yield pool, jobs
        except BrokenProcessPool:
            pool.shutdown(wait=False, cancel_futures=True)
            raise WorkerLost("a worker process died (killed, or out of memory)") from None
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise
        pool.shutdown()
        return
    client, cluster = _dask_client(scheduler, jobs, processes)
    try:
        workers = max(1, len(client.scheduler_info().get("workers", {})))
        yield client.get_executor(), workers
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
