"""The broad phase: listing every disk pair changes nothing but the listing."""
import numpy as np

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.model.body import RigidBody
from nonsmooth_rod.model.contacts import DiskOnDisk, DiskOnLine, Line
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.model.packing import pack_scene
from nonsmooth_rod.model.scene import Scene

R = 0.05


def _row(n, all_pairs):
    """n balls 1 mm apart on a floor, the first rolling into the others (a Newton's cradle with gaps)."""
    law = ContactLaw.of(0.3, 0.2, 0.9)
    bodies = [RigidBody(0.1, 0.4 * 0.1 * R * R, f"b{i}") for i in range(n)]
    contacts = [DiskOnLine(i, (0.0, 0.0), Line(), R, law, f"floor{i}") for i in range(n)]
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)] if all_pairs else [(i, i + 1) for i in range(n - 1)]
    contacts += [DiskOnDisk(j, i, R, R, law=law, name=f"{i}-{j}") for i, j in pairs]
    q0 = np.zeros(3 * n)
    q0[0::3], q0[1::3] = np.arange(n) * (2 * R + 1e-3), R
    v0 = np.zeros(3 * n)
    v0[0], v0[2] = 1.0, -1.0 / R
    return Scene(bodies, contacts), q0, v0


def test_all_pairs_listed_give_the_neighbours_run():
    # 15 listed pairs go through the broad phase (more than BROAD_PHASE_MIN_PAIRS), the 5 neighbour
    # pairs do not: the sorted and the unsorted run must agree
    from nonsmooth_rod.integrators.moreau_jean_loop import BROAD_PHASE_MIN_PAIRS

    assert 5 <= BROAD_PHASE_MIN_PAIRS < 15
    runs = [MoreauJean(MoreauJeanOptions(h=1e-3)).run(*_row(6, all_pairs), 0.1) for all_pairs in (False, True)]
    neighbours, everything = runs
    pair_impacts = [i.contact for i in neighbours.impacts if not i.contact.startswith("floor")]
    assert pair_impacts[:5] == ["0-1", "1-2", "2-3", "3-4", "4-5"]  # the impulse runs down the row
    assert [i.contact for i in everything.impacts] == [i.contact for i in neighbours.impacts]
    q = neighbours.trajectory.q  # the far pairs stay open: the same run to round-off of its positions
    assert np.max(np.abs(everything.trajectory.q - q)) <= 500 * np.finfo(float).eps * np.max(np.abs(q))
    far = [name for name in everything.contact_names if name not in neighbours.contact_names]
    assert len(far) == 10 and all(not everything.phases[n] or {p.mode for p in everything.phases[n]} == {"open"}
                                  for n in far)


def test_disk_pairs_are_packed_once_per_disk_and_sorted():
    packed = pack_scene(_row(4, True)[0])
    assert packed.disks.shape == (4, 3) and list(packed.disk_body) == [1, 0, 2, 3]  # first seen: body_a of 0-1
    assert np.all(np.diff(packed.pair_keys) > 0) and len(packed.pair_keys) == 6
