"""A one-step solver that fails stops the run with a message naming the step, time and states."""
import re

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.toys.blocks import BlockOnIncline


def test_gauss_seidel_without_iterations_fails_loudly():
    # a block launched up an incline on its two corners: a coupled pair, so Gauss–Seidel itself
    # runs (a single contact's step is solved in closed form, solvers/one_contact.py, and cannot fail)
    toy = BlockOnIncline(v0=1.0)
    q0, v0 = toy.initial_state()
    options = MoreauJeanOptions(h=1e-3, solver="pgs", solver_options={"max_iter": 1, "tol": 1e-300})
    res = MoreauJean(options).run(toy.scene(), q0, v0, 0.1)
    assert res.status == "failed"
    assert re.search(r"\(step \d+, t = [0-9.e-]+ s, contact states left:\w+, right:\w+, q = \[", res.message)
    assert res.events[-1].kind == "solver-failure"
