"""`nonsmooth-rod compile` fills the cache, and a cold compiled run says so once, truthfully."""
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.cli import main


@pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed")
def test_compile_marks_the_loop_warm_and_records_its_time(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    monkeypatch.setattr(_jit, "_warm", set())
    assert not _jit.engine_is_warm("moreau-jean")
    assert main(["compile"]) == 0
    assert "compiled in" in capsys.readouterr().out
    assert _jit.engine_is_warm("moreau-jean")
    assert main(["compile", "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    seconds, measured = _jit.compile_estimate_s("moreau-jean")
    assert measured and seconds >= 0.0


def test_the_notice_says_what_compiles_and_its_measured_time_once(tmp_path, monkeypatch):
    if not _jit.ENABLED:
        pytest.skip("numba not installed")
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    monkeypatch.setattr(_jit, "_warm", set())
    monkeypatch.setattr(_jit, "_noticed", set())
    said = []
    _jit.set_compile_notifier(said.append)
    try:
        with _jit.compiling("moreau-jean", "the Moreau–Jean loop"):
            pass  # cold: says it, then marks the part compiled with the time it took
        assert len(said) == 1 and "the Moreau–Jean loop" in said[0]
        assert "estimated" in said[0]
        with _jit.compiling("moreau-jean", "the Moreau–Jean loop"):
            pass
        assert len(said) == 1  # warm: nothing more to say
        (tmp_path / "moreau-jean.marker").unlink()
        monkeypatch.setattr(_jit, "_warm", set())
        monkeypatch.setattr(_jit, "_noticed", set())
        with _jit.compiling("moreau-jean", "the Moreau–Jean loop"):
            pass
        assert len(said) == 2 and "as measured on this machine" in said[1]
    finally:
        _jit.set_compile_notifier(None)
