"""Which samples become frames of an animation (shared by the rod's figures and any scene's)."""
from __future__ import annotations

import numpy as np


def frame_indices(t, n_frames: int) -> np.ndarray:
    """Samples nearest to n_frames evenly spaced times from the first to the last sample."""
    t = np.asarray(t, float)
    targets = np.linspace(t[0], t[-1], n_frames)
    idx = np.array([int(np.argmin(np.abs(t - tt))) for tt in targets])
    idx[-1] = len(t) - 1  # the very last state (after an impact, events repeat the time)
    return idx
