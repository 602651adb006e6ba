"""`import nonsmooth_rod` stays light: numba and the other heavy libraries load when a run needs
them, not at import (issue 25: the import ≤ 0.3 s), and the kernels made before numba loads
become numba's own dispatchers when it does."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

ROOT = Path(__file__).resolve().parents[1]
# What a plain import must not load: numba (and llvmlite, yaml and scipy, which numba imports),
# plotting, tables, sweeps' executors, the CLI's colours.
HEAVY = ("numba", "llvmlite", "yaml", "scipy", "matplotlib", "pandas", "dask", "rich", "PIL", "threadpoolctl")


def _run(code: str, **env_extra) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), **env_extra)
    env.pop("NONSMOOTH_ROD_NO_JIT", None)  # numba enabled (when installed): the decorators run as shipped
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip().splitlines()[-1]


@pytest.mark.parametrize("module", ["nonsmooth_rod", "nonsmooth_rod.cli"])
def test_the_import_loads_no_heavy_library(module):
    loaded = _run(f"import sys, {module}\nprint(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    assert loaded == "[]"


def test_numba_loads_on_first_use_and_the_package_then_calls_its_dispatchers():
    pytest.importorskip("numba")
    code = (
        "import sys\n"
        "from nonsmooth_rod import _jit\n"
        "from nonsmooth_rod.integrators import moreau_jean_loop as loop\n"
        "from nonsmooth_rod.model import forces\n"
        "assert 'numba' not in sys.modules\n"
        "before = loop.run_steps\n"
        "assert type(before) is _jit.LazyKernel and before.py_func.__name__ == 'run_steps'\n"
        "_jit.load_numba()\n"
        "from numba.core.dispatcher import Dispatcher\n"
        # every module global that named a lazy kernel names its dispatcher, in the kernel's own
        # module and where it was imported by name (the loop's accumulate_forces)
        "assert isinstance(loop.run_steps, Dispatcher) and loop.run_steps is before.dispatcher\n"
        "assert loop.run_steps.py_func is before.py_func\n"
        "assert isinstance(forces.accumulate_forces, Dispatcher)\n"
        "assert loop.accumulate_forces is forces.accumulate_forces\n"
        "assert loop.run_steps.targetoptions['_nrt'] is True\n"  # each decorator's options kept
        "assert loop._disk_reach.targetoptions['_nrt'] is False\n"  # (jit_borrowing)
        "late = _jit._kernel(lambda x: x + 1, {})\n"  # made after numba loaded: numba's at once
        "assert isinstance(late, Dispatcher)\n"
        "print('ok')\n"
    )
    if not _run("from nonsmooth_rod import _jit; print(_jit.ENABLED)") == "True":
        pytest.skip("numba disabled")
    assert _run(code) == "ok"


def test_threads_loading_numba_at_once_load_it_once():
    """Two threads' first compiled calls at the same moment: numba is loaded once, and both see
    every kernel as its one dispatcher (each LazyKernel's dispatcher made once)."""
    pytest.importorskip("numba")
    if not _run("from nonsmooth_rod import _jit; print(_jit.ENABLED)") == "True":
        pytest.skip("numba disabled")
    code = (
        "import threading\n"
        "from nonsmooth_rod import _jit\n"
        "from nonsmooth_rod.integrators import moreau_jean_loop as loop\n"
        "lazy = loop.run_steps\n"
        "made = []\n"
        "real = _jit._load_numba\n"
        "def counted():\n"
        "    made.append(1)\n"
        "    return real()\n"
        "_jit._load_numba = counted\n"
        "barrier = threading.Barrier(4)\n"
        "seen = []\n"
        "def first_use():\n"
        "    barrier.wait()\n"
        "    seen.append(lazy.materialized())\n"
        "threads = [threading.Thread(target=first_use) for _ in range(4)]\n"
        "[t.start() for t in threads]; [t.join() for t in threads]\n"
        "assert len(made) == 1 and len(seen) == 4 and all(d is loop.run_steps for d in seen), (made, seen)\n"
        "print('ok')\n"
    )
    assert _run(code) == "ok"
