"""The Delassus matrix W of a step's problem u = W p + q: its one block layout, and one
conversion per need the solvers have.

W has two rows (N, T) per contact. It is held either

* dense, 2 na × 2 na — Lemke's tableau and enum's modes need it; or
* block-sparse, the one block layout: CSR over contacts of 2×2 blocks, (indptr, indices,
  blocks) — contact a's blocks are blocks[indptr[a]:indptr[a + 1]] (each (N, T) × (N, T)), in
  the columns indices[indptr[a]:indptr[a + 1]], ascending, the diagonal block always present
  and the blocks of contacts that share no body left out. pgs sweeps it in O(nonzero blocks).

The compiled loop builds either form straight from the contacts' rows, with one block
computation (`moreau_jean_loop._block_entries`, called by `assemble_arrays` for the dense W and
by `delassus_blocks` for the blocks): that is the step's own assembly, not a conversion, and it
stays in the loop where the rows are. The conversions the solvers need are here, each once:

* `dense_to_blocks` — the blocks of a dense W (pgs given a dense problem: `solve(problem,
  "pgs")`, the kernels' `pgs_dense`, a step with joints);
* `group_matrix` — the dense W of one group of contacts, from whichever form the step holds
  (the per-group solves and the hold search; pgs's mode polish and its fallback to Lemke, the
  whole W as one group);
* `coupled_components` — the groups of contacts coupled through non-zero blocks, from either form.
"""
from __future__ import annotations

import numpy as np

from .._jit import jit, jit_borrowing


@jit_borrowing
def block_nonzero(W, i, j):
    """True when the 2×2 block of contacts i, j of the dense W has a non-zero entry."""
    return (W[2 * i, 2 * j] != 0.0 or W[2 * i, 2 * j + 1] != 0.0
            or W[2 * i + 1, 2 * j] != 0.0 or W[2 * i + 1, 2 * j + 1] != 0.0)


@jit
def dense_to_blocks(W):
    """CSR over contacts of the 2×2 blocks of W: (indptr, indices, blocks).

    Blocks that are exactly zero are left out, except the diagonal ones (always present).
    """
    indptr = np.zeros(W.shape[0] // 2 + 1, dtype=np.int64)
    nnz = count_blocks(W, indptr)
    indices, blocks = np.zeros(nnz, dtype=np.int64), np.zeros((nnz, 2, 2))
    fill_blocks(W, indptr, indices, blocks)
    return indptr, indices, blocks


@jit_borrowing
def count_blocks(W, indptr):
    """dense_to_blocks' row starts (indptr: contacts + 1 entries) in place; returns the blocks'
    number. With fill_blocks, the conversion into a caller's buffers (borrowing: no allocation)."""
    na = W.shape[0] // 2
    indptr[0] = 0
    for i in range(na):
        count = 0
        for j in range(na):
            if i == j or block_nonzero(W, i, j):
                count += 1
        indptr[i + 1] = indptr[i] + count
    return indptr[na]


@jit_borrowing
def fill_blocks(W, indptr, indices, blocks):
    """dense_to_blocks' columns and blocks, for the row starts count_blocks wrote."""
    na = W.shape[0] // 2
    for i in range(na):
        k = indptr[i]
        for j in range(na):
            if i == j or block_nonzero(W, i, j):
                indices[k] = j
                for r in range(2):
                    for s in range(2):
                        blocks[k, r, s] = W[2 * i + r, 2 * j + s]
                k += 1


@jit_borrowing
def blocks_to_dense(indptr, indices, blocks, W):
    """The whole dense W from its blocks, into W (2 na × 2 na; group_matrix of every contact,
    without allocating: pgs's fallback to Lemke in the step's scratch)."""
    for r in range(W.shape[0]):
        for c in range(W.shape[1]):
            W[r, c] = 0.0
    for a in range(indptr.shape[0] - 1):
        for k in range(indptr[a], indptr[a + 1]):
            b = indices[k]
            for r in range(2):
                for c in range(2):
                    W[2 * a + r, 2 * b + c] = blocks[k, r, c]


@jit
def coupled_components(indptr, indices, W, label):
    """Label the contacts by group of coupled contacts — those linked through non-zero blocks of
    W (contacts sharing a body, directly or along a chain) — from the block-sparse layout
    (indptr, indices) or, when indptr is empty, the dense W. Returns the number of groups."""
    na = label.shape[0]
    label[:] = -1
    stack = np.empty(na, dtype=np.int64)
    sparse = indptr.shape[0] > 0
    groups = 0
    for seed in range(na):
        if label[seed] >= 0:
            continue
        label[seed] = groups
        top = 1
        stack[0] = seed
        while top > 0:
            top -= 1
            i = stack[top]
            for k in range(indptr[i] if sparse else 0, indptr[i + 1] if sparse else na):
                j = indices[k] if sparse else k
                if label[j] < 0 and (sparse or block_nonzero(W, i, j)):
                    label[j] = groups
                    stack[top] = j
                    top += 1
        groups += 1
    return groups


@jit
def group_matrix(members, W, indptr, indices, blocks):
    """The dense W of one group of contacts (`members`, ascending), from W or its blocks."""
    n = members.shape[0]
    Wg = np.zeros((2 * n, 2 * n))
    position = np.full(indptr.shape[0] - 1 if indptr.shape[0] > 0 else W.shape[0] // 2, -1, dtype=np.int64)
    for a in range(n):
        position[members[a]] = a
    for a in range(n):
        i = members[a]
        if indptr.shape[0] > 0:
            for k in range(indptr[i], indptr[i + 1]):
                b = position[indices[k]]
                if b >= 0:
                    for r in range(2):
                        for c in range(2):
                            Wg[2 * a + r, 2 * b + c] = blocks[k, r, c]
        else:
            for b in range(n):
                for r in range(2):
                    for c in range(2):
                        Wg[2 * a + r, 2 * b + c] = W[2 * i + r, 2 * members[b] + c]
    return Wg


__all__ = ["block_nonzero", "dense_to_blocks", "count_blocks", "fill_blocks", "blocks_to_dense", "group_matrix",
           "coupled_components"]
