"""Disk–disk contact: a two-ball collision and a three-ball Newton's cradle.

Two balls (1 kg at 2 m/s, 3 kg at −0.5 m/s) collide with restitution e: Newton's law gives
v1' = (p − m2 e Δv)/(m1 + m2), v2' = (p + m1 e Δv)/(m1 + m2). Three equal touching balls, the
first arriving at v (e = 1): Moreau's law treats both contacts in one impact and gives
(−1/3, 2/3, 2/3) v — momentum and energy kept, but not the (0, 0, v) a real cradle shows.
With small gaps between the balls the impacts come one after the other and give (0, 0, v).

    python examples/ball_collisions.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    h = 1e-3
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), constrained_layout=True)
    for e, colour in ((1.0, "tab:blue"), (0.5, "tab:orange"), (0.0, "tab:green")):
        row = toys.BallRow(masses=(1.0, 3.0), radii=(0.05, 0.08), gaps=(0.1,), velocities=(2.0, -0.5), restitution=e)
        run = toys.run(row, "moreau-jean", 0.1, h=h)
        after = toys.ball_velocities(run)
        print(f"two balls, e = {e:g}: Moreau-Jean {np.round(after, 12)}, closed form {row.two_ball_outcome()}")
        for i, style in enumerate(("-", "--")):
            axes[0].plot(run.t, run.trajectory.v[:, 3 * i], style, color=colour, label=f"ball {i + 1}, e = {e:g}")
    axes[0].set(xlabel="t [s]", ylabel="velocity [m/s]", title="two balls (1 kg, 3 kg)")
    axes[0].legend(fontsize=7, ncol=3, loc="center left")
    for ax, gap in zip(axes[1:], (0.0, 0.01)):
        cradle = toys.BallRow.cradle(3, speed=1.0, gap=gap)
        run = toys.run(cradle, "moreau-jean", 0.15, h=h)
        after = toys.ball_velocities(run)
        expected = cradle.simultaneous_outcome() if gap == 0 else cradle.sequential_outcome()
        print(f"cradle, gaps {gap:g} m: Moreau-Jean {np.round(after, 12)} (expected {np.round(expected, 12)}; "
              "experiment (0, 0, 1))")
        for i in range(3):
            ax.plot(run.t, run.trajectory.q[:, 3 * i], label=f"ball {i + 1}: v' = {after[i]:+.3f}")
        title = "touching: one simultaneous impact" if gap == 0 else f"gaps of {gap * 100:g} cm: impacts in sequence"
        ax.set(xlabel="t [s]", ylabel="x of the centre [m]", title=title)
        ax.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "ball_collisions"))


if __name__ == "__main__":
    main()
