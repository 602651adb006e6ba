"""The README's library examples run as printed, and print what the README says they print."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_examples_run_and_print_what_they_claim(capsys, tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        exec(compile(code, str(README), "exec"), {"__name__": "readme"})
        printed = capsys.readouterr().out.strip()
        claimed = re.search(r"^# (.*?)(?:  —.*)?$", code.split("print(", 1)[1], flags=re.M)
        if claimed:  # a "# ..." line after the print states its output
            assert printed == claimed.group(1).strip()
