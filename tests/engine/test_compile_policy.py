"""No run waits for the compiler longer than it would take to run without it (_jit, issue 25)."""
import json
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import _jit
from nonsmooth_rod.toys.blocks import BlockOnIncline, slope_motion

pytestmark = pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed")
ROOT = Path(__file__).resolve().parents[2]


def _cold_run(monkeypatch, tmp_path, compile_seconds, t_end=0.05):
    """A block-on-incline run whose loop is taken as cold, with the given compile estimate;
    returns (result, background jobs asked for). Markers and locks go to tmp_path."""
    monkeypatch.setenv("NONSMOOTH_ROD_COMPILE", "auto")
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    monkeypatch.setattr(_jit, "_warm", set())
    monkeypatch.setattr(_jit, "engine_is_warm", lambda part="engine": False)
    monkeypatch.setattr(_jit, "compile_estimate_s", lambda part: (compile_seconds, True))
    started = []
    monkeypatch.setattr(_jit, "compile_in_background", lambda *args: started.append(args) or True)
    toy = BlockOnIncline(angle=math.radians(25.0), mu_s=0.3, mu_d=0.2)
    q0, v0 = toy.initial_state()
    return nr.simulate(toy.scene(), q0, v0, t_end, method="moreau-jean", h=1e-3, solver="lemke"), started


def test_a_run_shorter_than_compiling_goes_on_interpreted_and_compiles_in_background(monkeypatch, tmp_path):
    run, started = _cold_run(monkeypatch, tmp_path, compile_seconds=1e9)
    assert run.status == "ok" and not run.stats["compiled"]
    assert [args[0] for args in started] == ["moreau-jean"]
    toy = BlockOnIncline(angle=math.radians(25.0), mu_s=0.3, mu_d=0.2)  # tan 25° > μs: it slides
    _, velocity = slope_motion(run, toy)  # interpreted, the same physics: g (sin α − μd cos α)
    assert velocity[-1] == pytest.approx(toy.slope_velocity(run.trajectory.t[-1]), rel=1e-9)


def test_a_run_longer_than_compiling_compiles_now_and_goes_on_compiled(monkeypatch, tmp_path):
    run, started = _cold_run(monkeypatch, tmp_path, compile_seconds=0.0)
    assert run.status == "ok" and run.stats["compiled"] and started == []


def test_a_fresh_cache_runs_a_shipped_scene_at_once_and_compiles_in_a_detached_process(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), NONSMOOTH_ROD_COMPILE="auto",
               MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, "-m", "nonsmooth_rod.cli", "run", str(ROOT / "examples/scenes/ladder.toml"),
                          "--out", str(tmp_path / "run"), "--no-plot"],
                         env=env, capture_output=True, text=True, timeout=120)
    pid_files = list((tmp_path / "cache").glob("*.pid"))
    try:
        assert out.returncode == 0, out.stderr
        assert "running interpreted" in out.stderr and "in the background" in out.stderr
        summary = json.loads((tmp_path / "run" / "summary.json").read_text())
        assert summary["status"] == "ok"
        assert [p.name for p in pid_files] == [f"nonsmooth-rod-{nr.__version__}-moreau-jean.pid"]
    finally:
        for pid_file in pid_files:  # the compile itself is the slow part: not the suite's to wait for
            try:
                os.killpg(int(pid_file.read_text()), signal.SIGKILL)
            except (ProcessLookupError, PermissionError, ValueError):
                pass
