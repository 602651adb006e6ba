"""Figures and animations draw a driven obstacle at its place at each frame's time."""
from pathlib import Path

import numpy as np

from nonsmooth_rod.plots.animation import build_animation
from nonsmooth_rod.scenefile import load_scene, simulate_scene

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


def test_the_shaken_floor_is_drawn_where_its_motion_puts_it():
    result = simulate_scene(load_scene(SCENES / "shaken_block.toml", ["simulation.t_end=0.1",
                                                                      "simulation.moreau-jean.h=1e-3"]))
    anim = build_animation(result, frames=5)
    floor = [a for a in anim._fig.axes[0].lines if a.get_zorder() == 1 and len(a.get_xdata()) == 2][0]
    for k, t in enumerate(np.linspace(0.0, 0.1, 5)):
        anim._func(k)
        shift = floor.get_transform().transform((0.0, 0.0)) - anim._fig.axes[0].transData.transform((0.0, 0.0))
        expected = anim._fig.axes[0].transData.transform((0.02 * np.sin(4 * np.pi * t), 0.0)) \
            - anim._fig.axes[0].transData.transform((0.0, 0.0))
        np.testing.assert_allclose(shift, expected, atol=1e-6)
    # drawn by hand: no "deleted without rendering" warning when it is collected (in a later test)
    anim._draw_was_started = True
