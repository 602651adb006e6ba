"""`nonsmooth-rod compile` fills the cache, and a cold compiled run says so once, truthfully."""
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.cli import main


@pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed")
def test_compile_marks_the_solvers_parts_warm_and_records_their_time(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    monkeypatch.setattr(_jit, "_warm", set())
    assert not _jit.engine_is_warm("moreau-jean-lemke")
    assert main(["compile", "--solver", "lemke"]) == 0
    out = capsys.readouterr().out
    assert "compiled in" in out
    assert _jit.engine_is_warm("moreau-jean-lemke") and _jit.engine_is_warm("moreau-jean-lemke-step")
    assert not _jit.engine_is_warm("moreau-jean-pgs")  # asked for lemke only
    seconds, measured = _jit.compile_estimate_s("moreau-jean-lemke")
    assert measured and seconds >= 0.0


def test_compile_refuses_an_unknown_solver_in_one_line(capsys):
    assert main(["compile", "--solver", "osqp"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--solver" in err[0] and "osqp" in err[0]


def test_the_notice_says_what_compiles_and_its_measured_time_once(tmp_path, monkeypatch):
    if not _jit.ENABLED:
        pytest.skip("numba not installed")
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    monkeypatch.setattr(_jit, "_warm", set())
    monkeypatch.setattr(_jit, "_noticed", set())
    said = []
    _jit.set_compile_notifier(said.append)
    try:
        with _jit.compiling("moreau-jean-lemke", "the Moreau–Jean loop with solver lemke"):
            pass  # cold: says it, then marks the part compiled with the time it took
        assert len(said) == 1 and "the Moreau–Jean loop with solver lemke" in said[0]
        assert "estimated" in said[0]
        with _jit.compiling("moreau-jean-lemke", "the Moreau–Jean loop with solver lemke"):
            pass
        assert len(said) == 1  # warm: nothing more to say
        (tmp_path / "moreau-jean-lemke.marker").unlink()
        monkeypatch.setattr(_jit, "_warm", set())
        monkeypatch.setattr(_jit, "_noticed", set())
        with _jit.compiling("moreau-jean-lemke", "the Moreau–Jean loop with solver lemke"):
            pass
        assert len(said) == 2 and "as measured on this machine" in said[1]
    finally:
        _jit.set_compile_notifier(None)
