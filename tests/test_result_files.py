"""save / load / to_dataframe of any result, also one made in Python without a scene file."""
import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod import toys
from nonsmooth_rod.result_files import load, restart, save, to_dataframe
from nonsmooth_rod.validation import InputError


def test_a_python_made_result_round_trips_bit_for_bit(tmp_path):
    toy = toys.RockingBlock()
    result = nr.simulate(toy.scene(), *toy.initial_state(), 0.4, h=1e-3)
    save(result, tmp_path)
    again = load(tmp_path)
    for field in ("t", "q", "v", "normal_force", "tangential_force"):
        np.testing.assert_array_equal(getattr(again.trajectory, field), getattr(result.trajectory, field))
    assert again.trajectory.modes.tolist() == [[str(m) for m in row] for row in result.trajectory.modes]
    assert again.contact_names == result.contact_names and again.status == result.status
    assert [(i.t, i.contact) for i in again.impacts] == [(i.t, i.contact) for i in result.impacts]
    np.testing.assert_array_equal(again.impacts[0].v_after, result.impacts[0].v_after)
    assert {c: [p.as_dict() for p in ps] for c, ps in again.phases.items()} == \
        {c: [p.as_dict() for p in ps] for c, ps in result.phases.items()}
    assert list(to_dataframe(again).columns[:4]) == ["t", "body0.x", "body0.y", "body0.theta"]
    assert again.scene_file is None
    with pytest.raises(InputError, match="restart needs the scene"):
        restart(again, 0.1)


def test_load_refuses_a_folder_of_something_else(tmp_path):
    (tmp_path / "summary.json").write_text('{"schema": "nonsmooth-rod/summary/1"}')
    with pytest.raises(InputError, match="schema must be 'nonsmooth-rod/summary/2'"):
        load(tmp_path)
