"""Housner's rocking block on a rigid floor.

A uniform block (half-width b = 0.1 m, half-height c = 0.3 m, slenderness α = atan(b/c)) is
tilted by 10° onto a corner and released. It rocks about one corner, then the other; at each
impact the angular velocity is multiplied by 1 − (3/2) sin²α = 0.85 (angular momentum about
the landing corner is kept, e = 0, friction μ = 1 prevents sliding).

    python examples/rocking_block.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    block = toys.RockingBlock(half_width=0.1, half_height=0.3)
    runs = {"event-driven": toys.run(block, "event-driven", 2.0),
            "Moreau–Jean, h = 1e-3": toys.run(block, "moreau-jean", 2.0, h=1e-3),
            "Moreau–Jean, h = 1e-4": toys.run(block, "moreau-jean", 2.0, h=1e-4)}
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for (label, run), style in zip(runs.items(), ("-", "--", ":")):
        left.plot(run.t, np.degrees(run.trajectory.q[:, 2]), style, label=label)
        pairs = toys.impact_rate_pairs(run)
        ratios = [wa / wb for _, wb, wa in pairs]
        right.plot(range(1, len(ratios) + 1), ratios, "o" + style, label=label)
        print(f"{label}: ratios {', '.join(f'{r:.6f}' for r in ratios[:5])} (Housner {block.ratio:.6f})")
    left.set(xlabel="t [s]", ylabel="tilt θ [°]", title="rocking: one corner, then the other")
    left.legend(fontsize=8)
    right.axhline(block.ratio, color="k", lw=0.8, label="1 − (3/2) sin²α")
    right.set(xlabel="impact", ylabel="θ̇ after / θ̇ before", title=f"Housner's ratio, α = {np.degrees(block.slenderness):.2f}°")
    right.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "rocking_block"))


if __name__ == "__main__":
    main()
