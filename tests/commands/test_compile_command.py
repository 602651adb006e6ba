"""`nonsmooth-rod compile` fills the cache, and a cold compiled run says so once."""
import pytest

from nonsmooth_rod import _jit
from nonsmooth_rod.cli import main


@pytest.mark.skipif(not _jit.ENABLED, reason="numba not installed")
def test_compile_marks_the_engine_warm_and_says_so_only_when_cold(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(_jit, "_marker", lambda part="engine": tmp_path / f"{part}.marker")
    assert not _jit.engine_is_warm("moreau-jean-lemke")
    assert main(["compile"]) == 0
    out = capsys.readouterr().out
    assert "compiling the engine, once" in out and "compiled in" in out
    assert all(_jit.engine_is_warm(f"moreau-jean-{s}") for s in ("lemke", "pgs", "enum"))
    said = []
    _jit.set_compile_notifier(said.append)
    try:
        with _jit.compiling_notice(part="moreau-jean-lemke"):
            pass
        assert said == []  # warm: nothing to say
        (tmp_path / "moreau-jean-lemke.marker").unlink()
        with _jit.compiling_notice(part="moreau-jean-lemke"):
            pass
        assert said == [f"compiling the engine, once: ~{_jit.COMPILE_ESTIMATE_S} s"]
    finally:
        _jit.set_compile_notifier(None)
