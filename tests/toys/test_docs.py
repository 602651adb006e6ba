"""The code of docs/build-your-own-toy.md runs as printed and agrees with its closed form."""
import re
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod import _jit as nr_jit

DOC = Path(__file__).resolve().parents[2] / "docs" / "build-your-own-toy.md"


def _python_blocks(text):
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_walkthrough_code_runs_and_matches_its_closed_form(tmp_path, monkeypatch, capsys):
    blocks = _python_blocks(DOC.read_text(encoding="utf-8"))
    assert len(blocks) == 1
    code = blocks[0]
    assert len(code.strip().splitlines()) <= 40  # a short walk-through
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "walkthrough"}
    exec(compile(code, str(DOC), "exec"), namespace)
    run, ref = namespace["run"], namespace["ref"]
    t_roll, v0, h = namespace["t_roll"], namespace["v0"], 1e-3
    assert run.stats["compiled"] or not nr_jit.ENABLED
    for r, tol in ((run, h), (ref, 1e-9)):
        assert r.status == "ok"
        assert [ph.mode for ph in r.phases["floor"]] == ["slip+", "stick"]
        # rolls from t* = v0 / (3 μd g) (Moreau–Jean: within the step), at exactly (2/3) v0
        assert abs(r.phases["floor"][-1].t_start - t_roll) <= tol
        np.testing.assert_allclose(r.v[-1, 0], 2 * v0 / 3, rtol=1e-9)
        np.testing.assert_allclose(-0.1 * r.v[-1, 2], 2 * v0 / 3, rtol=1e-9)
    assert (tmp_path / "disk_thrown_without_spin.png").stat().st_size > 10_000
    printed = capsys.readouterr().out
    # the numbers quoted in the doc are the ones the code prints
    quoted = re.search(r"It prints\n\n```text\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S).group(1)
    assert printed.strip() == quoted.strip()


@pytest.mark.parametrize("name", ["toys.md", "build-your-own-toy.md"])
def test_doc_images_exist(name):
    text = (DOC.parent / name).read_text(encoding="utf-8")
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert images
    for rel in images:
        assert (DOC.parent / rel).is_file(), rel
