"""Suite-wide settings.

A cold compiled run normally goes on interpreted while the engine compiles in the background
(`_jit`). Tests that check the compiled engine must run it, so the suite compiles in-process
(`NONSMOOTH_ROD_COMPILE=wait`; a file lock lets one process compile each part while the others
wait for it); tests/engine/test_compile_policy.py checks the default policy in its own process.
On a cold cache the suite starts the loop's compile job in a detached process, with the
helper's share of the loop's callees in a second one (`_compile_split.start_share`: the job alone
does not split, the workers being busy collecting when it starts), so the tests that need no
compiled engine run while they compile, and a test that needs one waits only for what is left.
The workers run niced while the loop is cold: its compile is the suite's longest path (fresh
suite 192 → 182 s with the share, 167 s niced as well; docs/performance.md).

Which tests run first: the files marked `no_compiled_loop` (they never run the compiled
Moreau–Jean loop in-process — event-driven, solvers, validation, the fits — so they keep both
workers busy while the loop compiles), then the others, each group largest file first (xdist's own
balancing). The mark is checked: a marked test that enters the compiled loop fails, naming itself.
"""
import os

os.environ.setdefault("NONSMOOTH_ROD_COMPILE", "wait")


def pytest_configure(config):
    if hasattr(config.option, "loadscopereorder"):  # pytest-xdist ≥ 3.8: keep the order set below
        config.option.loadscopereorder = False
    from nonsmooth_rod import _jit

    if hasattr(config, "workerinput"):  # an xdist worker: the controller started the compiles
        if _jit.ENABLED and not _jit.engine_is_warm("moreau-jean") and hasattr(os, "nice"):
            os.nice(10)  # the loop's compile is the suite's longest path: the workers take the cores it leaves
        return

    if not _jit.ENABLED:
        return
    _jit.purge_stale_kernels()  # markers of edited sources do not count
    if not _jit.engine_is_warm("moreau-jean"):  # the one loop (runs with force callbacks use it too)
        _jit.start_compile_job("moreau-jean", [])
        # and the helper's share of its callees at once (the job alone does not split: the
        # workers are busy collecting when it starts, idle once the tests that need no loop ran)
        from nonsmooth_rod import _compile_split

        _compile_split.start_share(1)


import pytest  # noqa: E402


def pytest_collection_modifyitems(config, items):
    """Files marked no_compiled_loop first, then the rest; within each, the files with more tests first."""
    files = {}
    for item in items:
        files.setdefault(item.path, []).append(item)
    order = sorted(files.values(), key=lambda tests: (tests[0].get_closest_marker("no_compiled_loop") is None,
                                                      -len(tests)))
    items[:] = [item for tests in order for item in tests]


@pytest.fixture(autouse=True)
def _no_compiled_loop_is_true(request, monkeypatch):
    """A test marked no_compiled_loop fails if it enters the compiled loop (it would wait for the
    compile the mark promises it does not need)."""
    if request.node.get_closest_marker("no_compiled_loop") is None:
        return
    from nonsmooth_rod import _jit

    def refuse(part, what, prepare=None):
        pytest.fail(f"{request.node.nodeid} is marked no_compiled_loop but runs {what}: remove its mark")

    monkeypatch.setattr(_jit, "compiling", refuse)


@pytest.fixture
def no_space_for(monkeypatch):
    """`no_space_for("trajectory.csv")`: writing that file fails as on a full disk (ENOSPC), however
    it is written — through Path.write_text or a file nonsmooth_rod.io opens (write_csv streams
    blocks of rows into the atomic temporary)."""
    import builtins
    import errno
    import pathlib

    from nonsmooth_rod import io as nr_io

    def refuse(names):
        def full(name: str) -> bool:
            return any(name.startswith(f".{n}.") or name == n for n in names)

        real_write_text, real_open = pathlib.Path.write_text, builtins.open

        def write_text(self, text, *args, **kwargs):
            if full(self.name):
                raise OSError(errno.ENOSPC, "No space left on device")
            return real_write_text(self, text, *args, **kwargs)

        def open_(file, mode="r", *args, **kwargs):
            if any(c in mode for c in "wax") and full(pathlib.Path(file).name):
                raise OSError(errno.ENOSPC, "No space left on device")
            return real_open(file, mode, *args, **kwargs)

        monkeypatch.setattr(pathlib.Path, "write_text", write_text)
        monkeypatch.setattr(nr_io, "open", open_, raising=False)

    return lambda *names: refuse(names)
