"""The yardstick every benchmark reports against: one 3×3 `numpy.linalg.solve` in a plain Python
loop, timed in the same run (this machine's 2 cores are shared and noisy: ratios measured in one
run travel, absolute times do not). Process time, median of the repeats."""
from __future__ import annotations

import statistics
import time

import numpy as np


def yardstick_us(n: int = 20000, repeats: int = 5) -> float:
    """Microseconds of one 3×3 numpy.linalg.solve called from a Python loop (median of repeats)."""
    rng = np.random.default_rng(0)
    A = rng.standard_normal((3, 3)) + 3 * np.eye(3)
    b = rng.standard_normal(3)
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        for _ in range(n):
            np.linalg.solve(A, b)
        times.append((time.process_time() - t0) / n * 1e6)
    return statistics.median(times)
