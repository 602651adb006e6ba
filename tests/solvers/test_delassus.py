"""The Delassus W's one block layout and its conversions (solvers/delassus.py): the blocks of a
dense W, a group's dense W from either form, and the coupled groups from either form."""
from __future__ import annotations

import numpy as np
import pytest

from nonsmooth_rod.solvers.delassus import coupled_components, dense_to_blocks, group_matrix

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

EMPTY = np.zeros(0, dtype=np.int64)
NO_BLOCKS = np.zeros((0, 2, 2))


def _chains_w(seed: int = 0):
    """W = H M⁻¹ Hᵀ of two separate chains of bodies (contacts 0–2 on bodies 0–2, contacts 3–4 on
    bodies 3–4; contact 5 on body 5 alone), each contact's (N, T) rows on its one or two bodies:
    contacts sharing no body have an exactly zero block."""
    rng = np.random.default_rng(seed)
    bodies = [(0, 1), (1, 2), (2, -1), (3, 4), (4, -1), (5, -1)]
    H = np.zeros((2 * len(bodies), 18))
    for a, pair in enumerate(bodies):
        for body in pair:
            if body >= 0:
                H[2 * a:2 * a + 2, 3 * body:3 * body + 3] = rng.normal(size=(2, 3))
    minv = rng.uniform(0.5, 2.0, size=18)
    return (H * minv) @ H.T, [{0, 1, 2}, {3, 4}, {5}]


def test_blocks_of_a_dense_w_give_it_back_whole_and_by_group():
    W, _ = _chains_w()
    indptr, indices, blocks = dense_to_blocks(W)
    assert indptr.tolist() == [0, 2, 5, 7, 9, 11, 12]  # only the blocks of contacts sharing a body
    everyone = np.arange(W.shape[0] // 2)
    np.testing.assert_array_equal(group_matrix(everyone, W[:0, :0], indptr, indices, blocks), W)
    members = np.array([1, 2, 4])
    rows = np.ravel([[2 * a, 2 * a + 1] for a in members])
    expected = W[np.ix_(rows, rows)]
    np.testing.assert_array_equal(group_matrix(members, W[:0, :0], indptr, indices, blocks), expected)
    np.testing.assert_array_equal(group_matrix(members, W, EMPTY, EMPTY, NO_BLOCKS), expected)


def test_the_coupled_groups_are_the_same_from_either_form():
    W, groups = _chains_w(1)
    indptr, indices, _ = dense_to_blocks(W)
    from_blocks, from_dense = np.empty(6, dtype=np.int64), np.empty(6, dtype=np.int64)
    assert coupled_components(indptr, indices, W[:0, :0], from_blocks) == 3
    assert coupled_components(EMPTY, EMPTY, W, from_dense) == 3
    np.testing.assert_array_equal(from_blocks, from_dense)
    assert [set(np.flatnonzero(from_dense == g)) for g in range(3)] == groups
