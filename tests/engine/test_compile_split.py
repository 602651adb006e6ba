"""The loop's callees compiled on two cores before it (_compile_split), and the shipped shares kept
equal to what the loop's typing asks for (_loop_callees)."""
import os
import subprocess
import sys
import time

import numpy as np
import pytest

from nonsmooth_rod import _compile_split, _jit

pytestmark = pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed")

FAKE_PAIR = '''
import numba


@numba.njit(cache=True)
def double(a):
    return 2.0 * a[0]


@numba.njit(cache=True)
def square(a):
    return a[0] * a[0]


@numba.njit(cache=True)
def caller(a):
    return double(a) + square(a)
'''


def _fake_shares(tmp_path, monkeypatch, name: str, shares: str):
    """A module `name` (with the pair of jitted functions and their caller) and `name`_shares, importable
    here and in the helper (PYTHONPATH), cached beside them (numba's default, as in the helper)."""
    (tmp_path / f"{name}.py").write_text(FAKE_PAIR)
    (tmp_path / f"{name}_shares.py").write_text(f"SHARES = {shares}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    return f"{name}_shares"


def test_the_helper_compiles_its_share_into_the_cache_and_the_caller_finds_both(tmp_path, monkeypatch):
    name = f"fake_pair_{tmp_path.name.replace('-', '_')}"  # a module name of its own: no cache shared
    module = _fake_shares(tmp_path, monkeypatch, name, f"((({name!r}, 'double', '(float64[::1],)'),),"
                                                       f" (({name!r}, 'square', '(float64[::1],)'),))")
    monkeypatch.setattr(_compile_split, "usable_cores", lambda: 2)
    log = tmp_path / "helper.log"
    monkeypatch.setattr(_compile_split, "free_cores", lambda: 1)  # the other core busy: no helper
    assert not _compile_split.compile_callees(log, module) and not log.exists()
    monkeypatch.setattr(_compile_split, "free_cores", lambda: 2)
    assert _compile_split.compile_callees(log, module)
    assert "compiled share 1" in log.read_text()
    pair = sys.modules[name]
    (sig,) = pair.double.signatures  # this process's share, compiled here
    assert pair.square.signatures == []  # the helper's: not compiled here
    assert pair.caller(np.array([3.0])) == 15.0  # typing the caller asks for both
    assert pair.square.stats.cache_hits[sig] == 1 and not pair.square.stats.cache_misses  # found in the cache
    assert pair.double.stats.cache_misses[sig] == 1  # compiled once, by the share
    log.unlink()
    assert not _compile_split.compile_callees(log, module) and not log.exists()  # cached: no helper again


def test_a_share_started_in_the_background_lands_in_the_cache_once(tmp_path, monkeypatch):
    """start_share (the suite's conftest: the helper's share beside the loop's job) returns at
    once; its process compiles the share into the cache, and a cached share is not started again."""
    name = f"fake_pair_{tmp_path.name.replace('-', '_')}"
    module = _fake_shares(tmp_path, monkeypatch, name, f"((({name!r}, 'double', '(float64[::1],)'),),"
                                                       f" (({name!r}, 'square', '(float64[::1],)'),))")
    monkeypatch.setattr(_compile_split, "usable_cores", lambda: 2)
    assert not _compile_split.start_share(2, module)  # no such share
    split = _compile_split.shares(module)
    assert not _compile_split.in_cache(split[1])
    assert _compile_split.start_share(1, module)
    deadline = time.monotonic() + 120
    while not _compile_split.in_cache(split[1]) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _compile_split.in_cache(split[1]) and not _compile_split.in_cache(split[0])
    assert not _compile_split.start_share(1, module)  # cached: nothing to start
    monkeypatch.setattr(_compile_split, "usable_cores", lambda: 1)
    assert not _compile_split.start_share(0, module)  # one core: the loop's job compiles it


def test_shares_that_cannot_be_rebuilt_or_one_core_split_nothing(tmp_path, monkeypatch):
    name = f"fake_pair_{tmp_path.name.replace('-', '_')}"
    module = _fake_shares(tmp_path, monkeypatch, name, f"((({name!r}, 'double', '(NoSuchType[::1],)'),), ())")
    monkeypatch.setattr(_compile_split, "usable_cores", lambda: 2)
    assert _compile_split.shares(module) is None
    assert not _compile_split.compile_callees(tmp_path / "helper.log", module)
    monkeypatch.setattr(_compile_split, "usable_cores", lambda: 1)
    assert not _compile_split.compile_callees(tmp_path / "helper.log", _compile_split.SHARES_MODULE)
    assert not (tmp_path / "helper.log").exists()  # no helper started


def test_the_split_runs_inside_the_parts_lock_once_and_before_it_is_marked(monkeypatch, tmp_path):
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.compiled")
    monkeypatch.setattr(_jit, "_warm", set())
    monkeypatch.setattr(_jit, "_noticed", set())
    seen = []

    def prepare(log):
        seen.append((log.name, (tmp_path / "fake.compiled").exists()))

    with _jit.compiling("fake", "a fake part", prepare=prepare):
        pass
    with _jit.compiling("fake", "a fake part", prepare=prepare):  # warm now: nothing to prepare
        pass
    assert seen == [("fake.helper.log", False)] and (tmp_path / "fake.compiled").exists()


def test_the_shipped_shares_are_what_the_loops_typing_asks_for():
    """If this fails, the loop's callees or their arguments changed: `python -m
    nonsmooth_rod._loop_callees` writes the shares again (a stale entry only costs time: the loop
    compiles what it asks for itself). Typing the loop (~12 s of CPU) is skipped while the file's
    key is the sources' key: it was written from these very sources by this numba."""
    from nonsmooth_rod import _compile_shares, _loop_callees

    rebuilt = _compile_split.shares()
    assert rebuilt is not None and all(hasattr(d, "compile") for share in rebuilt for d, _ in share)
    shipped = {(d.py_func.__name__, tuple(args)) for share in rebuilt for d, args in share}
    assert len(shipped) == sum(len(share) for share in _compile_shares.SHARES)
    if _compile_shares.SOURCES == _loop_callees.sources_key():
        return
    callees = _loop_callees.loop_callees(_loop_callees.entry_args())
    assert _loop_callees.shares_source(callees, _compile_shares.SOURCES) == _loop_callees.SHARES_FILE.read_text()
    assert shipped == {(name, tuple(args)) for _, name, args in callees if _loop_callees.signature_text(args) is not None}


def test_the_shares_key_follows_every_source_but_the_shares_file(tmp_path, monkeypatch):
    import numba

    from nonsmooth_rod import _loop_callees

    (tmp_path / "solvers").mkdir()
    (tmp_path / "solvers" / "lemke.py").write_text("X = 1\n")
    (tmp_path / _loop_callees.SHARES_FILE.name).write_text("SHARES = ()\n")
    key = _loop_callees.sources_key(tmp_path)
    (tmp_path / _loop_callees.SHARES_FILE.name).write_text("SOURCES = 'k'\nSHARES = ()\n")
    assert _loop_callees.sources_key(tmp_path) == key  # writing the shares does not change it
    (tmp_path / "solvers" / "lemke.py").write_text("X = 2\n")
    edited = _loop_callees.sources_key(tmp_path)
    assert edited != key
    monkeypatch.setattr(numba, "__version__", numba.__version__ + ".post1")
    assert _loop_callees.sources_key(tmp_path) != edited  # another numba may type the loop otherwise


def test_free_cores_sees_a_busy_core():
    """A process spinning on one of this process's cores leaves it not free (/proc/stat's idle share)."""
    cores = _compile_split.usable_cores()
    if cores < 2 or not os.path.exists("/proc/stat"):
        pytest.skip("needs two cores and /proc/stat")
    spinner = subprocess.Popen([sys.executable, "-c", "import time\nt = time.time()\nwhile time.time() - t < 5: pass"])
    try:
        time.sleep(0.5)  # the spinner is running
        assert _compile_split.free_cores(0.5) <= cores - 1
    finally:
        spinner.kill()
        spinner.wait()
