"""Housner's earthquake problem: a slender block on a floor shaken horizontally.

The floor moves as x = A sin(2π f t) (A = 2 cm, f = 2 Hz; peak acceleration A ω² = 3.16 m/s²).
Friction holds (μs = 0.8 > b/c = 0.2), so the block rocks first, when the floor's acceleration
first reaches g b/c, at t = asin(g b / (c A ω²)) / ω. The scene is examples/scenes/shaken_block.toml.

    python examples/shaken_block.py [--out DIR]
"""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402
from nonsmooth_rod.scenefile import load_scene, simulate_scene  # noqa: E402

SCENE = Path(__file__).resolve().parent / "scenes" / "shaken_block.toml"


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    block = toys.ShakenBlock(half_width=0.05, half_height=0.25, mu_s=0.8)
    result = simulate_scene(load_scene(SCENE, ["simulation.t_end=0.6"]))
    onset = min(e.t for e in result.events if e.kind in ("liftoff", "stick-slip"))
    print(f"Moreau-Jean, h = 1e-4: rocks first at {onset:.6f} s, closed form {block.onset_time:.6f} s "
          f"(error {onset - block.onset_time:+.1e} s)")
    tr = result.trajectory
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True, constrained_layout=True)
    top.plot(tr.t, block.floor_acceleration(tr.t), label="floor acceleration")
    top.axhline(block.g * block.half_width / block.half_height, color="k", lw=0.8, ls=":", label="± g b/c")
    top.axhline(-block.g * block.half_width / block.half_height, color="k", lw=0.8, ls=":")
    top.axvline(block.onset_time, color="C3", lw=0.8, label="closed-form onset")
    top.set(ylabel="a [m/s²]", title="rocking block on a shaken floor")
    top.legend(fontsize=8)
    bottom.plot(tr.t, np.degrees(tr.q[:, 2]))
    bottom.axvline(block.onset_time, color="C3", lw=0.8)
    bottom.set(xlabel="t [s]", ylabel="tilt θ [°]")
    print("wrote", toys.save_figure(fig, args.out, "shaken_block"))


if __name__ == "__main__":
    main()
