"""Moreau–Jean's choice among a step's admissible solutions does not depend on the order in which
the scene lists its contacts, and keeps the scene's symmetries (issue 28, solvers.sticking).

Before: a symmetric pyramid of three disks short of friction between the disks slid to one side,
the side set by which top contact came first in the list; with pgs a pile of six disks took a
different motion (|Δq| 5e-2 m in 0.05 s) for one of three permutations of its contacts, and a pile
that holds (μs 0.5) collapsed in two of three orders: Lemke lifted two middle disks off the bottom
one, a solution the hold search did not look at (it now holds lifting contacts too)."""
import numpy as np
import pytest

import nonsmooth_rod as nr
from nonsmooth_rod.model.laws import ContactLaw
from nonsmooth_rod.toys import DiskPyramid, Ladder
from nonsmooth_rod.toys.stacks import ball_row, disk_pile

H, STEPS = 1e-3, 50
# Round-off of the exact solvers, grown over the run (a collapsing pile amplifies it: 7e-13 of
# its velocity scale measured); pgs stops each step at its relative residual 1e-9.
EXACT_TOL = 1e-10
PGS_TOL = 1e-9 * STEPS


def _pyramid():
    """μs between the disks 0.32 < tan(θ/2) = 1/3: the disks cannot hold, the floor can."""
    toy = DiskPyramid(spread=1.2, mu_disks=0.32, mu_disks_d=0.2, mu_floor=0.4, mu_floor_d=0.3)
    return (toy.scene(), *toy.initial_state())


def _ladder():
    toy = Ladder()
    return (toy.scene(), *toy.initial_state())


SCENES = {
    "pyramid": _pyramid,
    "ladder": _ladder,
    # without walls: friction alone holds the bottom row (or does not)
    "pile of six short of friction": lambda: disk_pile(3, law=ContactLaw.of(0.3, 0.2, 0.0), walls=False),
    "pile of six that holds": lambda: disk_pile(3, walls=False),
    "row of four balls": lambda: ball_row(4),
}
# enumeration takes groups of at most four contacts
CASES = [(solver, name) for solver in ("lemke", "pgs", "enum") for name in SCENES
         if solver != "enum" or name in ("pyramid", "ladder")]


def _run(scene, q0, v0, order, solver):
    listed = nr.Scene(scene.bodies, [scene.contacts[i] for i in order], gravity=scene.gravity)
    result = nr.simulate(listed, q0, v0, STEPS * H, h=H, solver=solver)
    assert result.status == "ok" and result.steps == STEPS
    return result


def _tolerance(solver, result):
    scale = max(np.max(np.abs(result.v)), 1.0)  # the velocities', and one second of them for q
    return (PGS_TOL if solver == "pgs" else EXACT_TOL) * scale


@pytest.mark.parametrize("solver,name", CASES)
def test_random_permutations_of_the_contacts_give_the_same_motion(solver, name):
    scene, q0, v0 = SCENES[name]()
    reference = _run(scene, q0, v0, range(len(scene.contacts)), solver)
    rng = np.random.default_rng(28)
    tol = _tolerance(solver, reference)
    for _ in range(3):
        result = _run(scene, q0, v0, rng.permutation(len(scene.contacts)), solver)
        assert np.max(np.abs(result.q - reference.q)) <= tol
        assert np.max(np.abs(result.v - reference.v)) <= tol
    if name == "pile of six that holds":
        assert np.max(np.abs(reference.q - q0)) <= tol  # at rest, whatever the order


def _mirrored(q):
    """The mirror image x → −x of the pyramid's state: the two lower disks swap, x and θ change sign."""
    m = q.reshape(q.shape[0], 3, 3)[:, [1, 0, 2], :].copy()
    m[:, :, 0] *= -1.0
    m[:, :, 2] *= -1.0
    return m.reshape(q.shape)


@pytest.mark.parametrize("solver", ["lemke", "pgs", "enum"])
def test_the_pyramid_short_of_friction_collapses_symmetrically_in_any_order(solver):
    """Listed in mirrored order (right before left) the motion is the mirror image of the motion
    listed left first — and both are symmetric: the top disk falls straight down while the lower
    disks roll apart on the floor."""
    scene, q0, v0 = _pyramid()
    motions = [_run(scene, q0, v0, order, solver) for order in ([0, 1, 2, 3], [1, 0, 3, 2], [0, 1, 3, 2])]
    tol = _tolerance(solver, motions[0])
    left_first, mirrored = motions[0], motions[1]
    assert np.max(np.abs(_mirrored(mirrored.q) - left_first.q)) <= tol
    assert np.max(np.abs(_mirrored(mirrored.v) - left_first.v)) <= tol
    for result in motions:
        assert np.max(np.abs(_mirrored(result.q) - result.q)) <= tol
        assert np.max(np.abs(result.q[:, 6])) <= tol  # the top disk's x
    q_end = left_first.q[-1]
    assert q0[7] - q_end[7] > 1e-5  # it collapses: the top disk falls, the lower ones part
    assert q_end[3] - q0[3] > 1e-6
    r = 0.1  # rolling without slip on the floor (floor μs 0.4 holds): x' = −r θ'
    assert left_first.v[-1, 3] == pytest.approx(-r * left_first.v[-1, 5], rel=1e-9)
