"""A one-step solver that fails stops the run with a message naming the step, time and states."""
import re

from nonsmooth_rod.integrators.moreau_jean import MoreauJean, MoreauJeanOptions
from nonsmooth_rod.rod.problem import RodProblem


def test_gauss_seidel_without_iterations_fails_loudly():
    p = RodProblem.paper(2)
    q0, v0 = p.initial_state()
    options = MoreauJeanOptions(h=1e-3, solver="pgs", solver_options={"max_iter": 1, "tol": 1e-300})
    res = MoreauJean(options).run(p.scene(), q0, v0, 0.1)
    assert res.status == "failed"
    assert re.search(r"\(step \d+, t = [0-9.e-]+ s, contact states A:\w+, B:\w+, q = \[", res.message)
    assert res.events[-1].kind == "solver-failure"
