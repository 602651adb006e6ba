"""Zeroed arrays carved out of one buffer per dtype.

The loop's per-run arrays (its `Work`, a window's `Records`) are a dozen small arrays each; a
scene's plan lends them from run to run (integrators/scene_plans.py) and zeroes them before
each: carved out of one buffer a dtype, a set is zeroed by one fill a dtype instead of one per
array (~0.25 µs each: a yardstick of a short run's fixed cost). Each array is a C-contiguous,
aligned view of its buffer — to the compiled loop the same type as an array of its own.
"""
from __future__ import annotations

import math

import numpy as np


def carve_zeros(specs) -> list:
    """Zeroed arrays of the given (shape, dtype)s, in order; those of one dtype share a buffer."""
    sizes: dict = {}
    for shape, dtype in specs:
        sizes[dtype] = sizes.get(dtype, 0) + math.prod(shape)
    buffers = {dtype: np.zeros(size, dtype=dtype) for dtype, size in sizes.items()}
    used = dict.fromkeys(sizes, 0)
    arrays = []
    for shape, dtype in specs:
        start = used[dtype]
        used[dtype] = start + math.prod(shape)
        arrays.append(buffers[dtype][start: used[dtype]].reshape(shape))
    return arrays


def owners(arrays) -> list:
    """The distinct arrays that own the data of `arrays` (each one's buffer, or itself): what
    zeroing them all fills."""
    found: dict = {}
    for a in arrays:
        owner = a if a.base is None else a.base
        found.setdefault(id(owner), owner)
    return list(found.values())


__all__ = ["carve_zeros", "owners"]
