"""A heap of boxes dropped into a bin (toys/box_heap.py), every pair of shapes searched: no box
passes through another, the floor or a wall (separating axes over every pair, independent of the
contact kernels), and the heap comes to rest. Compiled; a few seconds (the 50-box heap is
benchmarks/bench_shapes.py --peers)."""
import math

import numpy as np

import nonsmooth_rod as nr
from nonsmooth_rod.model.collision import deepest_overlap
from nonsmooth_rod.toys.box_heap import BoxHeap

H = 1e-3


def test_a_dropped_heap_of_boxes_rests_without_any_box_through_another():
    heap = BoxHeap(n=12, columns=4)
    scene = heap.scene()
    assert len(scene.contacts) == 12 * 11 // 2 * 32 + 12 * 3 * 4  # every pair, every box on the floor and walls
    q0, v0 = heap.initial_state()
    lines = list(heap.obstacles().values())
    assert deepest_overlap(scene.bodies, heap.shapes(), q0, lines) == 0.0
    result = nr.simulate(scene, q0, v0, 1.5, "moreau-jean", h=H, save_every=0.005)
    assert result.status == "ok", result.message[:200]
    # no deeper than one step of travel at the fastest fall (from the top layer's height)
    fastest = math.sqrt(2 * 9.81 * q0[1::3].max())
    assert deepest_overlap(scene.bodies, heap.shapes(), result.trajectory.q, lines) < H * fastest
    assert np.abs(result.trajectory.v[-1]).max() < 1e-6  # at rest


def test_the_fifty_box_heap_runs_with_pgs_where_gauss_seidel_needs_lemke_on_more_than_64_contacts():
    """Seed 1: at t ≈ 0.26 s a step has more active contacts than 64 that Gauss–Seidel cannot
    finish; Lemke on the dense W solves it (up to MAX_LEMKE_FALLBACK contacts). With the fallback
    limited to 64 the run fails there (checked: this test fails with MAX_LEMKE_FALLBACK = 64).
    Compiled only (~5 s)."""
    import pytest
    from nonsmooth_rod import _jit

    if not _jit.ENABLED:
        pytest.skip("numba not installed or disabled: interpreted, this run takes minutes")
    heap = BoxHeap(50, seed=1)
    scene, (q0, v0) = heap.scene(), heap.initial_state()
    result = nr.simulate(scene, q0, v0, 0.3, "moreau-jean", h=H, solver="pgs", save_every=0.01)
    assert result.status == "ok", result.message[:300]
    assert result.stats["solver_fallbacks"] > 0  # the steps Gauss–Seidel could not finish
    fastest = math.sqrt(2 * 9.81 * q0[1::3].max())
    lines = list(heap.obstacles().values())
    assert deepest_overlap(scene.bodies, heap.shapes(), result.trajectory.q, lines) < H * fastest
