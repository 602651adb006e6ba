"""The compile cache goes somewhere writable, and NUMBA_CACHE_DIR always wins."""
import os

import pytest

from nonsmooth_rod import _jit

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)


def _unset_cache_dir(monkeypatch):
    """NUMBA_CACHE_DIR absent for the test, and absent again after it: _choose_cache_dir may set it,
    and a bare delenv of an unset variable records nothing to undo — the setting leaked into the
    worker's environment, and every later subprocess (the memory benchmark's runs) compiled the
    engine from scratch into this test's folder (~2.5 min of a cold CI run)."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", "")  # records the original state, restored after the test
    monkeypatch.delenv("NUMBA_CACHE_DIR")


def test_a_read_only_package_folder_sends_the_cache_to_the_user_folder(monkeypatch, tmp_path):
    _unset_cache_dir(monkeypatch)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(_jit.os, "access", lambda path, mode: False)
    _jit._choose_cache_dir()
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "nonsmooth-rod" / "numba")
    assert (tmp_path / "nonsmooth-rod" / "numba").is_dir()


def test_numba_cache_dir_set_by_the_user_wins(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setattr(_jit.os, "access", lambda path, mode: False)
    _jit._choose_cache_dir()
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")


def test_a_writable_package_folder_keeps_numbas_default(monkeypatch):
    _unset_cache_dir(monkeypatch)
    monkeypatch.setattr(_jit.os, "access", lambda path, mode: True)
    _jit._choose_cache_dir()
    assert "NUMBA_CACHE_DIR" not in os.environ


# ------------------------------------------------------------ stale cached kernels
def test_changed_sources_drop_the_packages_cached_kernels_and_compile_markers(monkeypatch, tmp_path):
    package, cache = tmp_path / "pkg", tmp_path / "cache"
    package.mkdir()
    cache.mkdir()
    source = package / "loop.py"
    source.write_text("from .consts import K\n\n@jit\ndef run():\n    return K\n")
    (package / "consts.py").write_text("K = 1\n")
    (package / "cli.py").write_text("from .loop import run\n\ndef main():\n    return run()\n")
    monkeypatch.setattr(_jit, "_package_root", lambda: package)
    monkeypatch.setattr(_jit, "_cache_dir_of", lambda path: cache)
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": cache / f"nonsmooth-rod-9.9-{part}.compiled")

    def cached_files():
        for name in ("loop.run-10.py311.nbi", "loop.run-10.py311.1.nbc", "other.run-3.py311.nbi"):
            (cache / name).write_text("")
        (cache / "nonsmooth-rod-9.9-lemke.compiled").touch()

    def edit(path, text):  # a new size, so the check on sizes and times sees it on any file system
        path.write_text(text)

    cached_files()
    assert _jit.purge_stale_kernels()  # no digest yet: whatever is cached may be stale
    assert sorted(p.name for p in cache.iterdir()) == ["nonsmooth-rod-9.9-sources.digest", "other.run-3.py311.nbi"]
    cached_files()
    assert not _jit.purge_stale_kernels()  # the same sources: the cache stays
    assert (cache / "loop.run-10.py311.nbi").exists() and (cache / "nonsmooth-rod-9.9-lemke.compiled").exists()
    edit(package / "cli.py", "from .loop import run\n\ndef main():\n    return 2 * run()\n")
    assert not _jit.purge_stale_kernels()  # no kernel depends on the CLI: the cache stays
    assert (cache / "loop.run-10.py311.nbi").exists()
    edit(package / "consts.py", "K = 22\n")  # a constant a kernel compiled in: its cached code is stale
    assert _jit.purge_stale_kernels()
    assert not (cache / "loop.run-10.py311.nbi").exists() and not (cache / "loop.run-10.py311.1.nbc").exists()
    assert not (cache / "nonsmooth-rod-9.9-lemke.compiled").exists()
    cached_files()
    edit(source, "from .consts import K\n\n@jit\ndef run():\n    return K + 1\n")  # the kernel itself
    assert _jit.purge_stale_kernels()
    assert not (cache / "loop.run-10.py311.nbi").exists()


def test_the_kernel_sources_are_the_compiled_modules_and_what_they_import():
    names = {str(path.relative_to(_jit._package_root())) for path in _jit._package_sources()}
    assert {"integrators/moreau_jean_loop.py", "solvers/lemke.py", "solvers/kernels.py",
            "model/contact_kernels.py", "solvers/registry.py"} <= names
    assert not names & {"driver.py", "cli.py", "results.py", "studies/runner.py", "integrators/moreau_jean.py"}


def test_the_purged_folders_are_where_numba_caches_the_kernels():
    import pytest
    from pathlib import Path

    if not _jit.ENABLED:
        pytest.skip("numba not installed or disabled")
    from nonsmooth_rod.integrators import moreau_jean_loop
    from nonsmooth_rod.solvers import lemke

    for module, kernel in ((moreau_jean_loop, moreau_jean_loop.run_steps), (lemke, lemke._lemke_friction_into)):
        assert Path(kernel._cache._cache_path) == _jit._cache_dir_of(Path(module.__file__))


# ------------------------------------------------------------ BLAS threads
def test_blas_runs_on_one_thread_inside_a_run_and_its_limits_come_back_after():
    import pytest

    threadpoolctl = pytest.importorskip("threadpoolctl")
    import numpy  # noqa: F401

    with _jit.one_blas_thread():
        inside = [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]
    after = [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]
    assert inside and set(inside) == {1}
    with threadpoolctl.threadpool_limits(2, "blas"):
        before = [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"]
        with _jit.one_blas_thread():
            pass
        assert [lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"] == before
    assert len(after) == len(inside)


def test_nested_blas_limits_restore_once_at_the_outermost_exit():
    import pytest

    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads():
        return {lib["num_threads"] for lib in threadpoolctl.threadpool_info() if lib["user_api"] == "blas"}

    with threadpoolctl.threadpool_limits(2, "blas"):
        with _jit.one_blas_thread():  # a sweep's batch
            with _jit.one_blas_thread():  # one run inside it
                pass
            assert blas_threads() == {1}  # the inner exit does not lift the batch's limit
        assert blas_threads() == {2}


# ------------------------------------------------------------ without numba
def _without_numba(monkeypatch):
    monkeypatch.setattr(_jit, "HAVE_NUMBA", False)
    monkeypatch.setattr(_jit, "ENABLED", False)
    monkeypatch.setattr(_jit, "_warned", False)


def test_without_numba_the_cli_says_so_once_in_one_line_and_only_for_a_compiled_method(monkeypatch, tmp_path, capfd):
    from nonsmooth_rod.cli import main

    _without_numba(monkeypatch)
    monkeypatch.setattr(_jit, "_notifier", None)
    args = ["simulate", "--t-end", "0.02", "--no-plot", "--out", str(tmp_path)]
    assert main(args + ["--force"]) == 0  # event-driven: numba plays no part
    assert "numba" not in capfd.readouterr().err
    assert main(args + ["--method", "moreau-jean", "--h", "1e-3", "--force"]) == 0
    err = [line for line in capfd.readouterr().err.splitlines() if "numba" in line]
    assert err == [f"nonsmooth-rod: {_jit.NO_NUMBA_MESSAGE}"]
    assert main(args + ["--method", "moreau-jean", "--h", "1e-3", "--force"]) == 0
    assert "numba" not in capfd.readouterr().err  # once per process
    monkeypatch.setattr(_jit, "_warned", False)
    assert main(args + ["--method", "moreau-jean", "--h", "1e-3", "--force", "--quiet"]) == 0
    assert capfd.readouterr().err == ""


def test_without_numba_the_library_warns_once_for_a_moreau_jean_run(monkeypatch):
    import warnings

    import nonsmooth_rod as nr
    from nonsmooth_rod import toys

    _without_numba(monkeypatch)
    monkeypatch.setattr(_jit, "_notifier", None)
    ball = toys.BouncingBall()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        nr.simulate(ball.scene(), *ball.initial_state(), 0.01, method="event-driven")
        assert caught == []
        nr.simulate(ball.scene(), *ball.initial_state(), 0.01, h=1e-3)
        nr.simulate(ball.scene(), *ball.initial_state(), 0.01, h=1e-3)
    assert [str(w.message) for w in caught] == [_jit.NO_NUMBA_MESSAGE]
    assert caught[0].category is RuntimeWarning and caught[0].filename == __file__  # points at the caller


def test_the_cache_dir_chosen_in_a_test_does_not_outlive_it(monkeypatch, tmp_path):
    before = os.environ.get("NUMBA_CACHE_DIR")
    with monkeypatch.context() as patch:
        _unset_cache_dir(patch)
        patch.setenv("XDG_CACHE_HOME", str(tmp_path))
        patch.setattr(_jit.os, "access", lambda path, mode: False)
        _jit._choose_cache_dir()
        assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "nonsmooth-rod" / "numba")
    assert os.environ.get("NUMBA_CACHE_DIR") == before


RACING_KERNEL = '''
import os, sys, time
from nonsmooth_rod._jit import jit, load_numba

load_numba()  # its kernels are made after numba loaded: the path a late-imported module takes


@jit
def racer(a):
    total = 0.0
    for i in range(a.shape[0]):
        for j in range(a.shape[0]):
            total += a[i] * a[j] if i < j else a[i] - a[j]
    return total


if __name__ == "__main__":
    import numpy as np

    folder, me = sys.argv[1], sys.argv[2]
    open(os.path.join(folder, "ready-" + me), "w").close()
    while not all(os.path.exists(os.path.join(folder, f"ready-{i}")) for i in "01"):
        time.sleep(0.001)  # both processes call at the same moment
    racer(np.ones(3))
    (sig,) = racer.signatures
    print(racer.stats.cache_hits.get(sig, 0), racer.stats.cache_misses.get(sig, 0))
'''


def test_two_processes_compiling_one_kernel_at_once_compile_it_once(tmp_path):
    """The second waits for the first's compile (a lock per kernel) and loads it from the cache."""
    import subprocess
    import sys

    pytest.importorskip("numba")
    (tmp_path / "racing_kernel.py").write_text(RACING_KERNEL)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join(filter(None, [str(tmp_path), os.environ.get("PYTHONPATH")])))
    env.pop("NONSMOOTH_ROD_NO_JIT", None)
    racers = [subprocess.Popen([sys.executable, str(tmp_path / "racing_kernel.py"), str(tmp_path), str(i)],
                               env=env, stdout=subprocess.PIPE, text=True) for i in range(2)]
    counts = sorted(tuple(int(x) for x in r.communicate(timeout=300)[0].split()) for r in racers)
    assert counts == [(0, 1), (1, 0)]  # one compiled (a miss), the other found it (a hit)
