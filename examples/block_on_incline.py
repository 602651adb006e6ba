"""Block on an incline with static and dynamic friction (μs = 0.5, μd = 0.3).

Released from rest, a block sticks iff tan α ≤ μs and otherwise slides down with
g (sin α − μd cos α). Launched up the slope at 1 m/s it decelerates at g (sin α + μd cos α),
stops, and then stays (tan α ≤ μs) or slides back down with μd. The figure sweeps α for the
release and shows two launches, Moreau–Jean (h = 1 ms) against the closed form.

    python examples/block_on_incline.py [--out DIR]
"""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402

MU_S, MU_D, H = 0.5, 0.3, 1e-3


def measured_acceleration(run, toy):
    _, ds = toys.slope_motion(run, toy)
    return np.polyfit(run.t, ds, 1)[0]


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    angles = np.radians(np.arange(2.0, 46.0, 2.0))
    measured, exact = [], []
    for alpha in angles:
        block = toys.BlockOnIncline(angle=alpha, mu_s=MU_S, mu_d=MU_D)
        measured.append(measured_acceleration(toys.run(block, "moreau-jean", 0.3, h=H), block))
        exact.append(0.0 if block.holds else block.sliding_down_acceleration)
    measured, exact = np.array(measured), np.array(exact)
    print(f"release, {len(angles)} angles: max |a − closed form| = {np.max(np.abs(measured - exact)):.1e} m/s²")

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    fine = np.radians(np.linspace(0.0, 46.0, 400))
    left.plot(np.degrees(fine), np.where(np.tan(fine) <= MU_S, 0.0, -9.81 * (np.sin(fine) - MU_D * np.cos(fine))),
              color="k", lw=1, label="closed form")
    left.plot(np.degrees(angles), measured, "o", ms=4, label=f"Moreau–Jean, h = {H:g} s")
    left.axvline(math.degrees(math.atan(MU_S)), color="tab:red", ls=":", label="tan α = μs")
    left.set(xlabel="incline α [°]", ylabel="slope acceleration [m/s²]", title="released from rest")
    left.legend()

    for degrees, colour in ((20.0, "tab:blue"), (30.0, "tab:orange")):
        block = toys.BlockOnIncline(angle=math.radians(degrees), mu_s=MU_S, mu_d=MU_D, v0=1.0)
        run = toys.run(block, "moreau-jean", 0.6, h=H)
        _, ds = toys.slope_motion(run, block)
        fate = "stays" if block.holds else "slides back"
        right.plot(run.t, ds, color=colour, label=f"α = {degrees:g}°: stops at {block.stop_time:.4f} s, {fate}")
        right.plot(run.t, block.slope_velocity(run.t), "k--", lw=0.8)
        print(f"launch at α = {degrees:g}°: max velocity error {np.max(np.abs(ds - block.slope_velocity(run.t))):.1e} m/s "
              f"(within the stopping step), {fate}")
    right.set(xlabel="t [s]", ylabel="velocity up the slope [m/s]", title="launched up at 1 m/s (dashed: closed form)")
    right.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "block_on_incline"))


if __name__ == "__main__":
    main()
