"""Suite-wide settings.

A cold compiled run normally goes on interpreted while the engine compiles in the background
(`_jit`). Tests that check the compiled engine must run it, so the suite compiles in-process
(`NONSMOOTH_ROD_COMPILE=wait`; a file lock lets one process compile each part while the others
wait for it); tests/engine/test_compile_policy.py checks the default policy in its own process.
On a cold cache the suite starts both compiled loops (whole-run and step-wise) in detached
processes at once, so the tests that need no compiled engine run while they compile, and a test
that needs one waits only for what is left.
"""
import os

os.environ.setdefault("NONSMOOTH_ROD_COMPILE", "wait")


def pytest_configure(config):
    if hasattr(config, "workerinput"):  # an xdist worker: the controller started the compiles
        return
    from nonsmooth_rod import _jit

    if not _jit.ENABLED:
        return
    _jit.purge_stale_kernels()  # markers of edited sources do not count
    for part, args in (("moreau-jean", []), ("moreau-jean-step", ["--step"])):
        if not _jit.engine_is_warm(part):
            _jit.start_compile_job(part, args)
