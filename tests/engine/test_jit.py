"""The compile cache goes somewhere writable, and NUMBA_CACHE_DIR always wins."""
import os

from nonsmooth_rod import _jit


def test_a_read_only_package_folder_sends_the_cache_to_the_user_folder(monkeypatch, tmp_path):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
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
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(_jit.os, "access", lambda path, mode: True)
    _jit._choose_cache_dir()
    assert "NUMBA_CACHE_DIR" not in os.environ
