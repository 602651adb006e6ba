"""A solid disk released on an incline: rolling without slipping, or sliding.

It rolls iff tan α ≤ 3 μs, with slope acceleration (2/3) g sin α; otherwise it slides with
g (sin α − μd cos α) while its spin grows at 2 μd g cos α / R. The figure sweeps the incline
for μs = 0.3, μd = 0.2 and compares Moreau–Jean (h = 1 ms) and the event-driven reference with
both closed forms.

    python examples/disk_on_incline.py [--out DIR]
"""
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402

MU_S, MU_D = 0.3, 0.2


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    angles = np.radians(np.arange(5.0, 81.0, 5.0))
    measured = {"moreau-jean": [], "event-driven": []}
    worst = 0.0
    for alpha in angles:
        disk = toys.DiskOnIncline(angle=alpha, mu_s=MU_S, mu_d=MU_D)
        for method in measured:
            run = toys.run(disk, method, 0.3, h=1e-3)
            _, ds = toys.slope_motion(run, disk)
            a = -np.polyfit(run.t, ds, 1)[0]
            measured[method].append(a)
            worst = max(worst, abs(a + disk.slope_acceleration) / abs(disk.slope_acceleration))
    print(f"{len(angles)} angles × 2 methods: max relative acceleration error {worst:.1e}")
    fine = np.radians(np.linspace(1.0, 85.0, 400))
    g = 9.81
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    ax.plot(np.degrees(fine), 2 / 3 * g * np.sin(fine), "k-", lw=0.8, label="rolling: (2/3) g sin α")
    ax.plot(np.degrees(fine), g * (np.sin(fine) - MU_D * np.cos(fine)), "k--", lw=0.8, label="sliding: g (sin α − μd cos α)")
    ax.plot(np.degrees(angles), measured["moreau-jean"], "o", ms=6, mfc="none", label="Moreau–Jean, h = 1 ms")
    ax.plot(np.degrees(angles), measured["event-driven"], "x", ms=5, label="event-driven")
    ax.axvline(math.degrees(math.atan(3 * MU_S)), color="tab:red", ls=":", label="tan α = 3 μs")
    ax.set(xlabel="incline α [°]", ylabel="acceleration down the slope [m/s²]",
           title=f"Solid disk, μs = {MU_S}, μd = {MU_D}", ylim=(0.0, None))
    ax.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "disk_on_incline"))


if __name__ == "__main__":
    main()
