"""solvers.sticking: the dense simplex, and prefer_sticking on step problems with several solutions."""
import math

import numpy as np
import pytest
from scipy.optimize import linprog

from nonsmooth_rod.solvers import sticking
from nonsmooth_rod.solvers.sticking import (STATE_OPEN, STATE_SLIP_MINUS, STATE_SLIP_PLUS, STATE_STICK, prefer_sticking,
                                            simplex_max)
from nonsmooth_rod.toys import WedgedRod

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

H = 1e-3


def _interpreted(function):
    return getattr(function, "py_func", function)


# the inlined kernels (_jit.jit_inline: no dispatcher of their own in the loop): run as their bodies,
# their callees compiled — compiled on their own they would compile their callees' subtree again
_INLINED = ("_bordered_trials", "_bordered_split", "_relaxed_base", "_pruning_split")


def _compiled_or_body(name, compiled):
    function = getattr(sticking, name)
    return function if compiled and name not in _INLINED else _interpreted(function)


@pytest.mark.parametrize("compiled", [True, False])
def test_simplex_agrees_with_highs_on_random_lps(compiled):
    solve = simplex_max if compiled else _interpreted(simplex_max)
    rng = np.random.default_rng(7)
    seen = set()
    for trial in range(200):
        m, n = int(rng.integers(1, 8)), int(rng.integers(1, 6))
        G, h, c = rng.normal(size=(m, n)), rng.normal(size=m), rng.normal(size=n)
        if trial % 3 == 0:  # boxed: never unbounded
            G, h = np.vstack([G, np.eye(n)]), np.r_[h, np.full(n, 5.0)]
        x = np.zeros(n)
        status = solve(c, G, h, x)
        ref = linprog(-c, A_ub=G, b_ub=h, bounds=[(0, None)] * n, method="highs")
        expected = {0: 0, 2: 3, 3: 1}[ref.status]  # HiGHS: 2 infeasible, 3 unbounded
        if expected == 3 and linprog(np.zeros(n), A_ub=G, b_ub=h, method="highs").status == 0:
            expected = 1  # HiGHS's presolve calls some unbounded problems infeasible
        assert status == expected
        seen.add(status)
        if status == 0:
            assert c @ x == pytest.approx(-ref.fun, rel=1e-9, abs=1e-9)
            assert np.all(G @ x <= h + 1e-9) and np.all(x >= 0)
    assert seen == {0, 1, 3}  # optimal, unbounded and infeasible problems all occurred


@pytest.mark.parametrize("compiled", [True, False])
def test_the_pivot_on_the_pivot_rows_non_zeros_has_the_bits_of_the_full_update(compiled):
    """_pivot updates only the columns where the pivot row is non-zero (a hold search's tableau is
    mostly slack columns, zero in that row), each as one axpy over the rows of a tableau stored by
    columns; elsewhere the full Gauss–Jordan update would subtract an exact zero. So every entry
    must come out bit for bit as the full row-wise update's — the splits the search chooses cannot
    move (a tableau with 80 % zeros, and columns zero but in the pivot row)."""
    pivot = sticking._pivot if compiled else _interpreted(sticking._pivot)
    rng = np.random.default_rng(11)
    for _ in range(50):
        m, width = int(rng.integers(2, 30)), int(rng.integers(3, 60))
        T = rng.normal(size=(m, width)) * (rng.random((m, width)) < 0.2)
        r, j = int(rng.integers(m - 1)), int(rng.integers(width))
        T[(r + 1 + int(rng.integers(m - 1))) % m, :] = 0.0  # a row the pivot column does not touch
        T[r, j] = rng.normal() + 3.0  # a usable pivot
        expected = T.copy()
        expected[r, :] /= expected[r, j]
        for i in range(m):
            if i != r:
                expected[i, :] = expected[i, :] - expected[i, j] * expected[r, :]
        basis = np.zeros(m - 1, dtype=np.int64)
        by_columns = np.ascontiguousarray(T.T)  # the layout simplex_tableau carves: [column, row]
        pivot(by_columns, basis, r, j, np.empty(width, dtype=np.int64), np.empty(m))
        assert basis[r] == j
        assert np.array_equal(by_columns.T, expected)  # bits, not a tolerance


def _textbook_simplex(c, G, h):
    """max cᵀx, G x ≤ h, x ≥ 0 on a row-major tableau, pivot by pivot as Dantzig's textbook tableau
    with Dantzig's rule (Bland's after a degenerate pivot) and simplex_max's phase 1 (one auxiliary column entered at the most violated
    row): the reference the column-stored tableau must follow to the bit. Returns (status, x)."""
    m, n = G.shape
    T = np.zeros((m + 1, n + m + 2))
    T[:m, :n], T[:m, n], T[:m, -1] = G, -1.0, h
    T[np.arange(m), n + 1 + np.arange(m)] = 1.0
    basis = list(range(n + 1, n + m + 1))

    def pivot(r, j):
        T[r] /= T[r, j]
        for i in range(m + 1):
            if i != r and T[i, j] != 0.0:
                T[i] = T[i] - T[i, j] * T[r]
        basis[r] = j

    def objective(cost):
        T[m] = np.r_[cost, 0.0]
        for i in range(m):
            if cost[basis[i]] != 0.0:
                T[m] -= cost[basis[i]] * T[i]

    def run():
        bland = False
        for _ in range(50 * (n + m + 2)):
            entering = [j for j in range(n + m + 1) if T[m, j] > sticking.PIVOT_TOL]
            if not entering:
                return 0
            # Dantzig's rule (the largest reduced cost, the first of equals), Bland's (the lowest
            # index) right after a degenerate pivot
            j = entering[0] if bland else max(entering, key=lambda col: (T[m, col], -col))
            r = -1
            for i in range(m):
                if T[i, j] > sticking.PIVOT_TOL:
                    ratio = T[i, -1] / T[i, j]
                    if r < 0 or ratio < best - 1e-14 or (ratio <= best + 1e-14 and basis[i] < basis[r]):
                        best, r = ratio, i
            if r < 0:
                return 1
            pivot(r, j)
            bland = best <= sticking.DEGENERATE
        return 2

    cost = np.zeros(n + m + 1)
    worst = int(np.argmin(h)) if m else 0
    if m and h[worst] < 0.0:
        cost[n] = -1.0
        pivot(worst, n)
        objective(cost)
        if run() != 0 or -T[m, -1] < -1e-10 * (1.0 + np.max(np.abs(h))):
            return 3, None
        for i in range(m):
            if basis[i] == n:
                usable = [j for j in range(n + m + 1) if j != n and abs(T[i, j]) > sticking.PIVOT_TOL]
                if usable:
                    pivot(i, usable[0])
        cost[n] = 0.0
    T[:, n] = 0.0
    cost[:n] = c
    objective(cost)
    status, x = run(), np.zeros(n)
    for i in range(m):
        if basis[i] < n:
            x[basis[i]] = T[i, -1]
    return status, x


@pytest.mark.parametrize("compiled", [True, False])
def test_the_column_stored_simplex_takes_the_textbook_pivots_to_the_bit(compiled):
    """The hold search's tableau is stored by columns and each pivot updates only the pivot row's
    non-zero columns (issue 26): the same pivots (Dantzig's rule, Bland's after a degenerate pivot)
    must give the same bits as the textbook row-wise tableau — on random LPs with degenerate vertices (zeros in h, repeated rows) and
    infeasible and unbounded ones."""
    solve = simplex_max if compiled else _interpreted(simplex_max)
    rng = np.random.default_rng(5)
    statuses = set()
    for trial in range(150):
        m, n = int(rng.integers(1, 9)), int(rng.integers(1, 7))
        G = rng.normal(size=(m, n)) * (rng.random((m, n)) < 0.6)
        h = rng.normal(size=m) * (rng.random(m) < 0.7)  # zeros: degenerate vertices
        if m > 1 and trial % 4 == 0:
            G[-1], h[-1] = G[0], h[0]  # a repeated row
        if trial % 3 == 0:
            G, h = np.vstack([G, np.eye(n)]), np.r_[h, np.full(n, 4.0)]
        c = rng.normal(size=n)
        x = np.zeros(n)
        status = solve(c, G, h, x)
        expected_status, expected_x = _textbook_simplex(c, G, h)
        assert status == expected_status
        if status != 3:
            assert np.array_equal(x, expected_x)  # bits, not a tolerance
        statuses.add(status)
    assert statuses == {0, 1, 3}


def _step_problem(toy, h=H):
    """W and q of the first Moreau–Jean step of a toy released from rest (every contact active)."""
    scene = toy.scene()
    q0, v0 = toy.initial_state()
    rows = []
    for c in scene.kinematics(q0, v0):
        rows += [c.H_N, c.H_T]
    Hm = np.array(rows)
    W = Hm @ (scene.inverse_mass_diagonal[:, None] * Hm.T)
    q = Hm @ (v0 + h * scene.inverse_mass_diagonal * scene.force(0.0, q0, v0))
    return W, q


def _free_fall(q):
    """The solution every LCP solver returns for the wedged rod: the walls press on nothing."""
    return np.zeros_like(q), q.copy(), np.full(len(q) // 2, STATE_OPEN, dtype=np.int64)


def test_wedged_rod_is_held_when_some_split_can_hold_it():
    run = prefer_sticking
    toy = WedgedRod(angle=math.radians(30.0), mu_s=0.7, mu_d=0.5)
    W, q = _step_problem(toy)
    p, u, states = _free_fall(q)
    mu_s, mu_d = np.full(2, 0.7), np.full(2, 0.5)
    assert run(W, q, mu_s, mu_d, np.zeros(2), 1e-9 * np.max(np.abs(q)), np.zeros(2), p, u, states)
    assert list(states) == [STATE_STICK, STATE_STICK]
    np.testing.assert_allclose(u, W @ p + q, rtol=0, atol=500 * np.finfo(float).eps * np.max(np.abs(q)))
    assert np.max(np.abs(u)) < 1e-12 * np.max(np.abs(q))  # at rest at the end of the step
    pN, pT = p[0::2], p[1::2]
    assert np.all(pN > 0) and np.all(np.abs(pT) < 0.7 * pN)  # strictly inside both cones
    # friction carries the weight (wall tangents: left (0, −1), right (0, +1)); the walls squeeze
    assert pT[1] - pT[0] == pytest.approx(H * toy.mass * toy.g, rel=1e-9)
    assert pN[0] == pytest.approx(pN[1], rel=1e-9)


def test_wedged_rod_that_no_split_can_hold_keeps_falling():
    toy = WedgedRod(angle=math.radians(30.0), mu_s=0.5, mu_d=0.4)  # tan φ = 0.577 > μs
    W, q = _step_problem(toy)
    p, u, states = _free_fall(q)
    assert not prefer_sticking(W, q, np.full(2, 0.5), np.full(2, 0.4), np.zeros(2), 1e-12, np.zeros(2), p, u, states)
    assert np.all(p == 0) and np.all(u == q) and np.all(states == STATE_OPEN)


def _point_mass_on_floor(slip_speed, mass=2.0, g=9.81, h=H):
    """One point mass on a floor sliding at `slip_speed`: W = I/m, q = (−g h, v)."""
    return np.eye(2) / mass, np.array([-g * h, slip_speed])


@pytest.mark.parametrize("start_guess, held", [(0.0, True), (1.0, False)])
def test_only_contacts_that_started_at_rest_are_held(start_guess, held):
    # v = 0.9 μs g h: sticking (|p_T| = m v ≤ μs p_N) and sliding with μd = μs/2 both obey the law.
    mass, g, mu_s, mu_d = 2.0, 9.81, 0.4, 0.2
    v = 0.9 * mu_s * g * H
    W, q = _point_mass_on_floor(v, mass, g)
    p = np.array([mass * g * H, -mu_d * mass * g * H])  # the sliding solution
    u = W @ p + q
    states = np.array([STATE_SLIP_PLUS], dtype=np.int64)
    changed = prefer_sticking(W, q, np.array([mu_s]), np.array([mu_d]), np.array([start_guess]), 1e-15,
                              np.zeros(1), p, u, states)
    assert changed == held
    if held:  # a contact at rest starts sliding only when μs cannot hold it
        assert states[0] == STATE_STICK and abs(u[1]) < 500 * np.finfo(float).eps * v and p[1] == pytest.approx(-mass * v)
    else:  # a sliding contact keeps sliding while the law allows it (the sign iteration's choice)
        assert states[0] == STATE_SLIP_PLUS and u[1] > 0


def test_interpreted_source_gives_the_compiled_split():
    """NONSMOOTH_ROD_NO_JIT=1 runs every function of sticking.py as plain Python."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    code = "import json\nfrom test_sticking import wedge_split\nprint(json.dumps(wedge_split().tolist()))"
    src = Path(__file__).resolve().parents[2] / "src"
    env = dict(os.environ, NONSMOOTH_ROD_NO_JIT="1",
               PYTHONPATH=os.pathsep.join([str(src), str(Path(__file__).parent)]))
    out = subprocess.run([sys.executable, "-c", code], env=env,
                         capture_output=True, text=True, check=True)
    interpreted = np.array(json.loads(out.stdout.strip().splitlines()[-1]))
    compiled = wedge_split()
    scale = np.max(np.abs(compiled))
    np.testing.assert_allclose(interpreted, compiled, rtol=0, atol=500 * np.finfo(float).eps * scale)


def wedge_split():
    """The held split of the wedged rod's first step (compiled or not, as _jit decides)."""
    W, q = _step_problem(WedgedRod(angle=math.radians(30.0), mu_s=0.7, mu_d=0.5))
    p, u, states = _free_fall(q)
    assert prefer_sticking(W, q, np.full(2, 0.7), np.full(2, 0.5), np.zeros(2), 1e-9 * np.max(np.abs(q)),
                           np.zeros(2), p, u, states)
    return p


@pytest.mark.parametrize("told", [True, False])
def test_a_held_body_leaves_a_round_off_gap_open(told):
    # The wedged rod has drifted 1e-13 m towards the right wall: the left contact asks to close
    # that gap (u_N ≥ −g/h), which no squeeze can follow (W is singular); told which part of q
    # is gap closing, the step holds the rod and leaves the gap open.
    W, q = _step_problem(WedgedRod(angle=math.radians(30.0), mu_s=0.7, mu_d=0.5))
    closing = np.array([1e-13 / H, 0.0])
    q[0] += closing[0]
    p, u, states = _free_fall(q)
    held = prefer_sticking(W, q, np.full(2, 0.7), np.full(2, 0.5), np.zeros(2), 1e-9 * np.max(np.abs(q)),
                           closing if told else np.zeros(2), p, u, states)
    assert held == told
    if told:
        assert list(states) == [STATE_STICK, STATE_STICK]
        # H_N v = 0 on both, to round-off of the step's velocities
        assert u[0] == pytest.approx(closing[0], rel=1e-6) and abs(u[2]) < 500 * np.finfo(float).eps * np.max(np.abs(q))


# ------------------------------------------------------------ groups of coupled contacts
def _two_wedged_rods():
    """The step of two wedged rods in one problem (block-diagonal W): the first holdable
    (μs > tan φ), the second not; both start falling freely."""
    held, falls = WedgedRod(angle=math.radians(30.0), mu_s=0.7, mu_d=0.5), \
        WedgedRod(angle=math.radians(30.0), mu_s=0.5, mu_d=0.4)
    (W1, q1), (W2, q2) = _step_problem(held), _step_problem(falls)
    W = np.zeros((8, 8))
    W[:4, :4], W[4:, 4:] = W1, W2
    return W, np.r_[q1, q2], np.array([0.7, 0.7, 0.5, 0.5]), np.array([0.5, 0.5, 0.4, 0.4]), (W1, q1)


@pytest.mark.parametrize("compiled", [True, False])
def test_coupled_components_dense_and_block_sparse(compiled):
    from nonsmooth_rod.solvers.delassus import dense_to_blocks
    from nonsmooth_rod.solvers.delassus import coupled_components

    label_of = coupled_components if compiled else _interpreted(coupled_components)
    rng = np.random.default_rng(3)
    for _ in range(50):  # random block patterns: contacts i, j coupled iff their block is non-zero
        n = int(rng.integers(1, 9))
        coupled = np.triu(rng.random((n, n)) < 0.25, 1)
        coupled = coupled | coupled.T | np.eye(n, dtype=bool)
        W = np.kron(coupled, np.ones((2, 2))) * rng.uniform(0.5, 1.0, (2 * n, 2 * n))
        dense, sparse = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
        empty = np.zeros(0, dtype=np.int64)
        groups = label_of(empty, empty, W, dense)
        indptr, indices, _ = dense_to_blocks(W)
        assert label_of(indptr, indices, np.zeros((0, 0)), sparse) == groups
        np.testing.assert_array_equal(dense, sparse)
        # the same partition as the connected components of the coupling graph (closure by squaring)
        reach = coupled.astype(int)
        for _ in range(n):
            reach = np.minimum(reach @ reach, 1)
        assert groups == len({tuple(row) for row in reach})
        for i in range(n):
            for j in range(n):
                assert (dense[i] == dense[j]) == bool(reach[i, j])


def test_each_group_is_held_alone_as_if_it_were_the_whole_step():
    from nonsmooth_rod.solvers._common import python_body
    from nonsmooth_rod.solvers.sticking import prefer_sticking_by_group

    run = python_body(prefer_sticking_by_group)  # (the loop's compiled kernels; it exists only inlined)
    W, q, mu_s, mu_d, (W1, q1) = _two_wedged_rods()
    p, u, states = _free_fall(q)
    tol = 1e-9 * np.max(np.abs(q))
    empty = np.zeros(0, dtype=np.int64)
    assert run(W, empty, empty, np.zeros((0, 2, 2)), q, mu_s, mu_d, np.zeros(4), tol, np.zeros(4), p, u, states, 64,
               np.zeros(0))
    p1, u1, states1 = _free_fall(q1)
    assert prefer_sticking(W1, q1, mu_s[:2], mu_d[:2], np.zeros(2), tol, np.zeros(2), p1, u1, states1)
    # the holdable rod gets exactly its own held split; the other keeps falling, untouched
    np.testing.assert_array_equal(p[:4], p1)
    np.testing.assert_array_equal(states[:2], states1)
    assert np.all(p[4:] == 0.0) and np.all(u[4:] == q[4:]) and np.all(states[2:] == STATE_OPEN)
    # a group larger than max_group keeps the solver's answer
    p, u, states = _free_fall(q)
    assert not run(W, empty, empty, np.zeros((0, 2, 2)), q, mu_s, mu_d, np.zeros(4), tol, np.zeros(4), p, u,
                   states, 1, np.zeros(0))
    assert np.all(p == 0.0)


def test_candidates_no_split_can_hold_are_pruned_and_the_others_still_held():
    """One problem, four candidates (both rods' wall contacts slide from rest): the falling rod's
    two are pruned (not holdable even with every other candidate free), the holdable rod is held."""
    run = prefer_sticking
    W, q, mu_s, mu_d, (W1, q1) = _two_wedged_rods()
    p, u, states = _free_fall(q)
    tol = 1e-9 * np.max(np.abs(q))
    assert run(W, q, mu_s, mu_d, np.zeros(4), tol, np.zeros(4), p, u, states)
    assert list(states) == [STATE_STICK, STATE_STICK, STATE_OPEN, STATE_OPEN]
    assert np.max(np.abs(u[:4])) <= 1e-9 * np.max(np.abs(q))  # the held rod ends the step at rest
    assert np.all(p[4:] == 0.0) and np.all(u[4:] == q[4:])  # the other falls, untouched
    assert p[3] - p[1] == pytest.approx(H * 9.81, rel=1e-9)  # friction carries the held rod's weight


def _exhaustive_hold(W, q, mu_s, mu_d, p, u, states, tol):
    """The held set without pruning, written from the rule's statement: the candidates are the
    touching contacts and the lifting ones (all started at rest); every subset, largest first,
    sticks it and slides the other candidates (their own slip direction, or against their
    friction) or lets them lift; the largest admissible
    set wins if it is the only one of its size, else the search goes on among the subsets of the
    tied sets' intersection. Returns the final set of sticking contacts, or None (nothing
    admissible, or the solver's own mode)."""
    from itertools import combinations

    from nonsmooth_rod.solvers.sticking import MODE_OPEN, MODE_SLIDE, MODE_STICK, admissible_split

    na = len(mu_s)
    lifting = [i for i in range(na) if u[2 * i] > tol and states[i] == STATE_OPEN]
    cand = sorted(lifting + [i for i in range(na) if abs(u[2 * i]) <= tol
                             and (abs(u[2 * i + 1]) > tol or p[2 * i + 1] != 0.0)])
    if not lifting and all(abs(u[2 * i + 1]) <= tol for i in cand):
        return None
    release = {i: 0.0 if i in lifting else np.sign(u[2 * i + 1]) if abs(u[2 * i + 1]) > tol else
               -np.sign(p[2 * i + 1]) for i in cand}
    scale = max(np.max(np.abs(p)), np.max(np.abs(q)) / np.max(np.abs(W)))
    allowed = set(cand)
    while True:
        for size in range(len(allowed), -1, -1):
            found = []
            for held in combinations(sorted(allowed), size):
                mode = np.array([MODE_STICK if (i in held or (i not in cand and states[i] == STATE_STICK)) else
                                 (MODE_OPEN if states[i] == STATE_OPEN and (i not in cand or release[i] == 0.0)
                                  else MODE_SLIDE) for i in range(na)], dtype=np.int64)
                sign = np.array([0.0 if mode[i] != MODE_SLIDE else
                                 (release[i] if i in cand else np.sign(u[2 * i + 1])) for i in range(na)])
                if admissible_split(W, q, mu_s, mu_d, mode, sign, tol, scale, np.zeros(2 * na)):
                    found.append(set(held))
            if found:
                break
        if not found:
            return None
        if len(found) == 1:  # None too when it is the solver's own mode
            if found[0] == {i for i in cand if states[i] == STATE_STICK}:
                return None
            return sorted(found[0] | {i for i in range(na) if i not in cand and states[i] == STATE_STICK})
        allowed = set.intersection(*found)


def _block_diagonal(*problems):
    n = sum(len(q) for _, q in problems)
    W, k = np.zeros((n, n)), 0
    for Wi, qi in problems:
        W[k:k + len(qi), k:k + len(qi)] = Wi
        k += len(qi)
    return W, np.concatenate([qi for _, qi in problems])


def _lemke_start(W, q, mu_s):
    """The step's Lemke solution under the μs interval (slip guess 0) and its contact states."""
    from nonsmooth_rod.solvers import PlanarFrictionProblem, solve

    sol = solve(PlanarFrictionProblem(W, q, -mu_s, mu_s), "lemke")
    tol = 1e-9 * np.max(np.abs(q))
    states = np.array([STATE_OPEN if sol.p[2 * i] <= 1e-12 * np.max(np.abs(sol.p), initial=1e-300) else
                       STATE_STICK if abs(sol.u[2 * i + 1]) <= tol else
                       (STATE_SLIP_PLUS if sol.u[2 * i + 1] > 0 else STATE_SLIP_MINUS) for i in range(len(mu_s))],
                      dtype=np.int64)
    return np.array(sol.p), np.array(sol.u), states


def _rod(deg, mu):
    return _step_problem(WedgedRod(angle=math.radians(deg), mu_s=mu, mu_d=0.8 * mu)), [mu, mu]


def _pyramid(mu_disks, mu_floor):
    from nonsmooth_rod.toys import DiskPyramid

    toy = DiskPyramid(mu_disks=mu_disks, mu_disks_d=0.8 * mu_disks, mu_floor=mu_floor, mu_floor_d=0.8 * mu_floor)
    return _step_problem(toy), [mu_floor, mu_floor, mu_disks, mu_disks]


CASES = {  # several holdable and unholdable groups in one step problem (the pyramid short of friction
    # holds its floor contacts, not one top contact: the mirror images of that mode tie)
    "two rods, one holds": [_rod(30.0, 0.7), _rod(30.0, 0.5)],
    "three rods, two hold": [_rod(20.0, 0.4), _rod(35.0, 0.6), _rod(35.0, 0.75)],
    "pyramid that holds and a rod that falls": [_pyramid(0.34, 0.12), _rod(30.0, 0.5)],
    "pyramid short of friction and a rod that holds": [_pyramid(0.32, 0.12), _rod(30.0, 0.7)],
}


@pytest.mark.parametrize("case", list(CASES))
def test_pruned_search_holds_the_same_contacts_as_the_exhaustive_one(case):
    parts = CASES[case]
    W, q = _block_diagonal(*(problem for problem, _ in parts))
    mu_s = np.concatenate([mu for _, mu in parts])
    mu_d = 0.8 * mu_s
    p, u, states = _lemke_start(W, q, mu_s)
    n = len(mu_s)
    tol = 1e-9 * np.max(np.abs(q))
    expected = _exhaustive_hold(W, q, mu_s, mu_d, p, u, states, tol)
    held = prefer_sticking(W, q, mu_s, mu_d, np.zeros(n), tol, np.zeros(n), p, u, states)
    assert held == (expected is not None)
    if held:
        assert sorted(np.flatnonzero(states == STATE_STICK)) == expected


def test_a_previous_split_that_still_holds_is_reused_and_one_that_does_not_is_not():
    """A body held at rest meets the same problem every step: the previous step's split, which
    holds it to round-off, is the answer (no LP); a split that leaves it moving is not."""
    from nonsmooth_rod.solvers.sticking import prefer_sticking_from

    W, q = _step_problem(WedgedRod(angle=math.radians(30.0), mu_s=0.7, mu_d=0.5))
    mu_s, mu_d, tol = np.full(2, 0.7), np.full(2, 0.5), 1e-9 * np.max(np.abs(q))
    p, u, states = _free_fall(q)
    assert prefer_sticking(W, q, mu_s, mu_d, np.zeros(2), tol, np.zeros(2), p, u, states)
    held = p.copy()
    squeeze = np.linalg.svd(W)[2][-1]  # W's null space: impulses that move nothing
    previous = held + 0.01 * np.max(np.abs(held)) * squeeze  # still held, not the deepest split
    assert np.max(np.abs(W @ previous + q)) <= 1e-12 * np.max(np.abs(q))
    p, u, states = _free_fall(q)
    assert prefer_sticking_from(W, q, mu_s, mu_d, np.zeros(2), tol, np.zeros(2), p, u, states, previous)
    np.testing.assert_array_equal(p, previous)
    moving = 0.5 * held  # half the impulse: the rod would fall
    p, u, states = _free_fall(q)
    assert prefer_sticking_from(W, q, mu_s, mu_d, np.zeros(2), tol, np.zeros(2), p, u, states, moving)
    np.testing.assert_array_equal(p, held)  # the LP's split again


def test_the_split_margin_without_unknowns_is_the_simplex_optimum():
    """_deepest_split with no null-space unknown (a mode that fixes the split) skips the simplex:
    its closed form max t s.t. weight·t ≤ h, t ≤ 1 (−inf for a violated hard row) agrees with
    simplex_max on the same LP to round-off (issue 26)."""
    from nonsmooth_rod.solvers.sticking import _fixed_split_margin
    rng = np.random.default_rng(26)
    infeasible = 0
    for _ in range(300):
        m = int(rng.integers(1, 20))
        h = rng.normal(size=m)
        weight = (rng.random(m) < 0.6).astype(float)
        G = np.vstack([np.c_[weight, -weight], [[1.0, -1.0]]])  # t = t⁺ − t⁻
        x = np.zeros(2)
        status = simplex_max(np.array([1.0, -1.0]), G, np.r_[h, 1.0], x)
        closed = _fixed_split_margin(h, weight)
        if status != 0:
            assert closed == -np.inf
            infeasible += 1
        else:
            assert closed == pytest.approx(x[0] - x[1], rel=1e-12, abs=1e-12)
    assert 0 < infeasible < 300


def test_the_least_squares_without_svd_vouches_only_for_full_rank():
    """_full_row_rank_solution (a QR and a triangular inverse in place of LAPACK's SVD, one per LP of
    the hold search) certifies A's full row rank at RANK_TOL only when the SVD would find it: then
    x0 is the minimum-norm solution and Z an orthonormal basis of A's null space; a rank-deficient
    or nearly so A (the SVD's rank below m) is never certified — the caller takes the SVD."""
    from nonsmooth_rod.solvers import sticking
    solve = _interpreted(sticking._full_row_rank_solution)  # (inlined: its callees run compiled)
    rng = np.random.default_rng(3)
    certified = deficient = 0
    for trial in range(300):
        m = int(rng.integers(1, 10))
        n = int(rng.integers(m, 14))
        A, b = rng.normal(size=(m, n)), rng.normal(size=m)
        if trial % 3 == 0 and m > 1:  # a repeated row, up to a perturbation at or below RANK_TOL
            A[-1] = 2.0 * A[0] + rng.normal(size=n) * 10.0 ** rng.uniform(-18, -10)
        ok, x0, Z = solve(A, b)
        s = np.linalg.svd(A, compute_uv=False)
        if s[-1] <= sticking.RANK_TOL * s[0]:  # the SVD's rank is below m
            deficient += 1
            assert not ok
        if not ok:
            continue
        certified += 1
        x_ref = np.linalg.pinv(A) @ b
        assert np.max(np.abs(x0 - x_ref)) <= 1e3 * np.finfo(float).eps * (s[0] / s[-1]) * np.max(np.abs(x_ref))
        assert Z.shape == (n, n - m)
        np.testing.assert_allclose(Z.T @ Z, np.eye(n - m), atol=1e-13)
        assert np.max(np.abs(A @ Z), initial=0.0) <= 1e-13 * s[0]
    assert certified > 150 and deficient > 50  # both kinds occurred


def _row_cluster(rng, balls):
    """A step of `balls` touching balls on a floor, the first driven into the others, some of the
    others rolling or sliding a little (random μs ≥ μd): W, q, μs, μd and Lemke's answer under μs."""
    from nonsmooth_rod.model.laws import ContactLaw
    from nonsmooth_rod.toys import stacks

    mu = rng.uniform(0.05, 0.6)
    scene, q0, v0 = stacks.ball_row(balls, gap=0.0, law=ContactLaw.of(mu, mu * rng.uniform(0.5, 1.0), 0.0))
    v0[0::3] = rng.uniform(-0.3, 0.3, balls) * (rng.random(balls) < 0.5)
    v0[0] = rng.uniform(0.2, 2.0)
    v0[2::3] = -v0[0::3] / stacks.BALL_RADIUS * rng.uniform(0.0, 1.2, balls)
    rows = []
    for c in scene.kinematics(q0, v0):
        rows += [c.H_N, c.H_T]
    Hm = np.array(rows)
    W = Hm @ (scene.inverse_mass_diagonal[:, None] * Hm.T)
    q = Hm @ (v0 + H * scene.inverse_mass_diagonal * scene.force(0.0, q0, v0))
    mu_s = np.array([c.law.friction.mu_s for c in scene.contacts])
    mu_d = np.array([c.law.friction.mu_d for c in scene.contacts])
    return (W, q, mu_s, mu_d) + _lemke_start(W, q, mu_s)


def _search_start(kernel, rng):
    """A random row cluster at its Lemke start and what a hold search starts from: the tolerance,
    the impulse scale, the resting candidates (_resting_contacts) and empty mode and sign arrays."""
    W, q, mu_s, mu_d, p, u, states = _row_cluster(rng, int(rng.integers(3, 7)))
    na = len(mu_s)
    tol = 1e-9 * np.max(np.abs(q))
    scale = max(np.max(np.abs(p)), np.max(np.abs(q)) / np.max(np.abs(W)))
    candidates, release = np.empty(na, dtype=np.int64), np.empty(na)
    n_c = kernel("_resting_contacts")(np.zeros(na), p, u, np.zeros(na), states, tol, candidates, release, False)
    return (W, q, mu_s, mu_d, p, u, states, tol, scale, candidates, release, n_c,
            np.zeros(na, dtype=np.int64), np.zeros(na))


@pytest.mark.parametrize("compiled", [True, False])
def test_held_set_trials_through_the_shared_factorization_are_the_general_ones(compiled):
    """A held-set trial solved by bordering the all-released mode (_bordered_split: one QR per
    search, a Schur complement per trial) decides as admissible_split does on the same mode, with
    the same split to round-off, whenever it vouches for the trial (a bordered matrix of full rank);
    a trial whose mode leaves freedom in the split is never vouched for (the general LP takes it).
    Every trial of small row clusters (issue 26: the row of 16's held-set trials, 143 LPs)."""
    def kernel(name):
        return _compiled_or_body(name, compiled)
    rng = np.random.default_rng(26)
    vouched = declined = admissible = 0
    for _ in range(12 if compiled else 4):
        W, q, mu_s, mu_d, p, u, states, tol, scale, candidates, release, n_c, mode, sign = _search_start(kernel, rng)
        na = len(mu_s)
        shared = kernel("_bordered_trials")(W, mu_d, candidates, release, n_c, u, states, mode, sign,
                                            *kernel("search_scratch")(na))
        for held in range(1 << n_c):
            kernel("_modes_for")(held, candidates, release, n_c, u, states, mode, sign, False)
            p_fast, p_general = np.zeros(2 * na), np.zeros(2 * na)
            found = kernel("_bordered_split")(shared, held, W, q, mu_s, mode, sign, tol, scale, p_fast)
            expected = kernel("admissible_split")(W, q, mu_s, mu_d, mode, sign, tol, scale, p_general)
            if found < 0:
                declined += 1
                P, rows = sticking._unknowns(mode, sign, mu_d)
                assert len(rows) < P.shape[1] or np.linalg.matrix_rank((W @ P)[rows]) < len(rows) \
                    or np.linalg.cond((W @ P)[rows]) > 1e6  # vouched for whenever a unique split is clear
                continue
            vouched += 1
            assert found == int(expected)
            if expected:
                admissible += 1
                assert np.max(np.abs(p_fast - p_general)) <= 1e-12 * scale
    assert vouched > 50 and declined > 5 and admissible > 5  # every kind occurred


def test_the_search_on_small_row_clusters_holds_what_the_exhaustive_search_holds(monkeypatch):
    """prefer_sticking (pruning, held-set trials through the shared factorization, compiled) against
    the rule written out (_exhaustive_hold: every subset, largest first, each by admissible_split) on
    random clusters of 3–5 balls hit by the first: the same held set, or the solver's answer both
    ways — wherever the rule needs at most MAX_TRIALS LPs (beyond, the search keeps the solver's
    answer by design, friction.md)."""
    rng = np.random.default_rng(5)
    general, lps = sticking.admissible_split, [0]

    def counted(*args):
        lps[0] += 1
        return general(*args)
    compared = held_cases = 0
    for _ in range(40):
        W, q, mu_s, mu_d, p, u, states = _row_cluster(rng, int(rng.integers(3, 5)))
        na, tol = len(mu_s), 1e-9 * np.max(np.abs(q))
        lps[0] = 0
        monkeypatch.setattr(sticking, "admissible_split", counted)
        expected = _exhaustive_hold(W, q, mu_s, mu_d, p, u, states, tol)
        monkeypatch.setattr(sticking, "admissible_split", general)
        held = prefer_sticking(W, q, mu_s, mu_d, np.zeros(na), tol, np.zeros(na), p, u, states)
        if lps[0] > sticking.MAX_TRIALS:
            continue
        compared += 1
        assert held == (expected is not None)
        if held:
            held_cases += 1
            assert sorted(np.flatnonzero(states == STATE_STICK)) == expected
            assert np.max(np.abs(u[1::2][states == STATE_STICK]), initial=0.0) <= tol  # held: at rest to the tolerance
    assert compared >= 20 and held_cases >= 1  # (the held cases of other groups: CASES above)


def _law_ratio(W, q, mode, sign, mu_s, p, tol, scale):
    """The largest of each law quantity the final check (_split_obeys_law) reads over its tolerance:
    1 is the check's boundary."""
    u, ratios = W @ p + q, []
    for i, m in enumerate(mode):
        if m == sticking.MODE_SLIDE:
            ratios.append(-sign[i] * u[2 * i + 1] / tol)
        if m == sticking.MODE_STICK:
            ratios.append(abs(u[2 * i + 1]) / tol)
        if m in (sticking.MODE_STICK, sticking.MODE_SLIDE, sticking.MODE_FREE):
            ratios.append(abs(u[2 * i]) / tol)
        if m != sticking.MODE_OPEN:
            ratios.append(-p[2 * i] / (sticking.MARGIN_TOL * scale))
        if m in (sticking.MODE_STICK, sticking.MODE_FREE, sticking.MODE_LOOSE):
            ratios.append((abs(p[2 * i + 1]) - mu_s[i] * p[2 * i]) / (sticking.MARGIN_TOL * scale))
    return max(ratios)


@pytest.mark.parametrize("compiled", [True, False])
def test_pruning_lps_on_the_shared_relaxation_decide_as_the_general_ones(compiled):
    """A pruning LP solved on the relaxation factored once per search (_pruning_split: the LP's
    equations are the relaxation's and the held candidate's 1–2 rows) decides as admissible_split on
    the same mode. Its deepest split is a vertex of a face of optima found in another basis, often
    with a sliding contact's slip on the LP's hard bound; that bound keeps LP_SHARE of the final
    check's tolerance, so every optimal vertex passes the check and the two decide alike (with the
    bound at the tolerance itself, before issue 26, round-off split them). Every pruning LP of
    small row clusters; the shared path must vouch for most of them."""
    def kernel(name):
        return _compiled_or_body(name, compiled)
    rng = np.random.default_rng(27)
    vouched = declined = admissible = 0
    for _ in range(12 if compiled else 4):
        W, q, mu_s, mu_d, p, u, states, tol, scale, candidates, release, n_c, mode, sign = _search_start(kernel, rng)
        na = len(mu_s)
        relaxed = kernel("_relaxed_base")(W, mu_d, candidates, release, n_c, u, states, mode, sign,
                                          *kernel("search_scratch")(na))
        for c in range(n_c):
            kernel("_modes_for")(1 << c, candidates, release, n_c, u, states, mode, sign, True)
            i = candidates[c]
            added = np.array([2 * i + 1]) if release[c] != 0.0 else np.array([2 * i, 2 * i + 1])
            p_shared, p_general = np.full(2 * na, np.nan), np.full(2 * na, np.nan)
            found = kernel("_pruning_split")(relaxed, added, W, q, mu_s, mode, sign, tol, scale, p_shared)
            expected = kernel("admissible_split")(W, q, mu_s, mu_d, mode, sign, tol, scale, p_general)
            if found < 0:
                declined += 1
                continue
            vouched += 1
            assert found == int(expected)
            admissible += bool(expected)
    assert vouched > 20 and admissible >= 5 and vouched >= 4 * declined


@pytest.mark.parametrize("compiled", [True, False])
def test_the_trials_small_inverse_is_the_packages_lu_inverse(compiled):
    """_small_inverse (a held-set trial's Schur complement, through kernel_base's LU into scratch)
    inverts the leading s × s block of its input to round-off of its condition (against numpy's
    inverse), and fills infinities for a singular block — which then fail _bordered_split's
    certificate (a finite Frobenius norm is required)."""
    invert = sticking._small_inverse if compiled else _interpreted(sticking._small_inverse)
    rng = np.random.default_rng(5)
    for s in range(0, 9):
        S = np.full((12, 12), np.nan)  # entries beyond the block must not be read
        S[:s, :s] = rng.normal(size=(s, s)) + 3.0 * np.eye(s)
        LU, inverse = np.empty((s, s)), np.empty((s, s))
        invert(S, s, LU, np.empty(s, dtype=np.int64), inverse)
        expected = np.linalg.inv(S[:s, :s]) if s else np.zeros((0, 0))
        condition = np.linalg.cond(S[:s, :s]) if s else 1.0
        size = max(1.0, np.abs(expected).max(initial=0.0))
        assert np.allclose(inverse, expected, rtol=0.0, atol=50 * condition * np.finfo(float).eps * size)
    singular = np.array([[1.0, 2.0], [2.0, 4.0]])
    inverse = np.empty((2, 2))
    invert(singular, 2, np.empty((2, 2)), np.empty(2, dtype=np.int64), inverse)
    assert np.all(np.isinf(inverse))


def _bland_only(T, basis, n_allowed, max_iter, cols, factors):
    """_run_simplex with Bland's rule at every pivot (the lowest index enters): main's rule before
    issue 26's Dantzig pivots, to compare the vertices the two rules reach."""
    m, rhs = T.shape[1] - 1, T.shape[0] - 1
    for _ in range(max_iter):
        entering = [col for col in range(n_allowed) if T[col, m] > sticking.PIVOT_TOL]
        if not entering:
            return 0
        j, r, best = entering[0], -1, np.inf
        for i in range(m):
            if T[j, i] > sticking.PIVOT_TOL:
                ratio = T[rhs, i] / T[j, i]
                if ratio < best - 1e-14 or (ratio <= best + 1e-14 and r >= 0 and basis[i] < basis[r]):
                    best, r = ratio, i
        if r < 0:
            return 1
        sticking._pivot(T, basis, r, j, cols, factors)
    return 2


def test_a_pruning_decision_does_not_depend_on_the_vertex_the_pivot_rule_reaches(monkeypatch):
    """The pruning LP's deepest split is a vertex of a face of optima, where a sliding contact's
    slip often sits on the LP's hard bound. With that bound at the final check's own tolerance
    (LP_SHARE = 1, main's rule before issue 26) Bland's and Dantzig's rules reach different optimal
    vertices and round-off then accepts one and rejects the other: some pruning decisions of small
    row clusters differ. With the bound at LP_SHARE of the tolerance every optimal vertex passes
    the check by the rest, so both rules decide every LP alike — and each accepted split keeps its
    law quantities within LP_SHARE of their tolerances (+ round-off). Interpreted (the module's
    globals patched: Bland's rule is this test's reference, not a switch of the compiled code)."""
    for name, value in list(vars(sticking).items()):
        if hasattr(value, "py_func"):
            monkeypatch.setattr(sticking, name, value.py_func)
    rules = (_bland_only, sticking._run_simplex)
    rng = np.random.default_rng(26)
    differ = {1.0: 0, sticking.LP_SHARE: 0}
    lps = accepted = 0
    for _ in range(6):
        W, q, mu_s, mu_d, p, u, states, tol, scale, candidates, release, n_c, mode, sign = _search_start(
            lambda name: getattr(sticking, name), rng)
        for c in range(n_c):
            sticking._modes_for(1 << c, candidates, release, n_c, u, states, mode, sign, True)
            lps += 1
            for share in differ:
                monkeypatch.setattr(sticking, "LP_SHARE", share)
                decisions, splits = [], []
                for rule in rules:
                    monkeypatch.setattr(sticking, "_run_simplex", rule)
                    splits.append(np.zeros_like(q))
                    decisions.append(sticking.admissible_split(W, q, mu_s, mu_d, mode, sign, tol, scale, splits[-1]))
                differ[share] += decisions[0] != decisions[1]
                if share < 1.0 and decisions[0]:
                    accepted += 1
                    for split in splits:
                        assert _law_ratio(W, q, mode, sign, mu_s, split, tol, scale) <= share + 1e-6
    assert differ[1.0] >= 1  # the knife edge occurs on these clusters (main's rule)
    assert differ[sticking.LP_SHARE] == 0  # and no longer decides
    assert lps >= 30 and accepted >= 5
