"""Scene keys by dotted path: entries by name, '*' for every entry, a vector's component, two
keys moving together; and the one-line refusals."""
from __future__ import annotations

from pathlib import Path

import pytest

from nonsmooth_rod.studies.paths import apply_sets, check_path, current_value, with_values
from nonsmooth_rod.validation import InputError

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

DATA = {"schema": "x", "gravity": 9.81,
        "contacts": [{"name": "left", "law": {"mu_s": 0.6, "mu_d": 0.4}},
                     {"name": "right", "law": {"mu_s": 0.6, "mu_d": 0.4}}],
        "initial": {"block": {"q": [0.0, 0.025, 0.0], "v": [0.1, 0.0, 0.0]}},
        "title": "belt"}


def test_paths_select_entries_components_and_every_entry():
    assert current_value(DATA, "contacts.right.law.mu_d") == 0.4
    assert current_value(DATA, "initial.block.v.0") == 0.1
    out = with_values(DATA, {"contacts.*.law.mu_s": 0.7, "gravity,initial.block.v.0": 0.2})
    assert [c["law"]["mu_s"] for c in out["contacts"]] == [0.7, 0.7]
    assert out["gravity"] == 0.2 and out["initial"]["block"]["v"] == [0.2, 0.0, 0.0]
    assert DATA["contacts"][0]["law"]["mu_s"] == 0.6  # the original is left alone
    assert apply_sets(DATA, ["contacts.*.law.mu_d=0.1"])["contacts"][1]["law"]["mu_d"] == 0.1


def test_a_key_the_file_leaves_to_its_default_has_no_current_value():
    assert current_value(DATA, "contacts.left.law.restitution") is None


@pytest.mark.parametrize("path,message", [
    ("contacts.middle.law.mu_s", "no entry named 'middle'"),
    ("title", "not a number"),
    ("initial.block.v.7", "has no entry '7'"),
    ("gravity.x", "is a value, not a table"),
    ("bodies.block.mass", "has no key 'bodies'"),
    ("contacts..mu_s", "expected a dotted path"),
])
def test_paths_that_name_nothing_or_no_number_are_refused(path, message):
    with pytest.raises(InputError, match=message):
        current_value(DATA, path)


def test_a_path_the_schema_does_not_know_is_refused(tmp_path):
    from nonsmooth_rod.scenefile import read_data

    data, _ = read_data(Path(__file__).resolve().parents[2] / "examples" / "scenes" / "ladder.toml")
    assert check_path(data, "contacts.foot.law.mu_s", 0.3, "--axis") == 0.5
    with pytest.raises(InputError, match="unknown key"):
        check_path(data, "contacts.foot.law.friction", 0.3, "--axis")
