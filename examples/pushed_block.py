"""Stick–slip onset: a block pushed along the floor by a force ramp F = 10 N/s · t.

Static friction holds it until F reaches μs N (t* = μs m g / rate = 0.4905 s); then it slides
and the friction drops to μd N, so the acceleration jumps from 0 to (μs − μd) g. Moreau–Jean
(h = 1 ms) and the event-driven reference against the closed form.

    python examples/pushed_block.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    block = toys.PushedBlock(rate=10.0, mu_s=0.5, mu_d=0.3)
    h = 1e-3
    runs = {"Moreau–Jean": toys.run(block, "moreau-jean", 0.8, h=h), "event-driven": toys.run(block, "event-driven", 0.8)}
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    N = block.mass * block.g
    for (label, run), style in zip(runs.items(), ("-", "--")):
        onset = toys.first_slip_time(run)
        tr = run.trajectory
        friction = -tr.tangential_force.sum(axis=1)
        left.plot(run.t[1:], friction[1:], style, label=f"{label}: slips at {onset:.4f} s")
        right.plot(run.t, tr.v[:, 0], style, label=label)
        print(f"{label}: onset {onset:.6f} s (closed form {block.onset_time:.6f} s, error "
              f"{(onset - block.onset_time) / h:+.2f} h), max velocity error "
              f"{np.max(np.abs(tr.v[:, 0] - block.velocity(run.t))):.1e} m/s")
    left.plot(run.t, block.push(run.t), color="0.6", lw=0.8, label="push F(t)")
    left.axhline(block.mu_s * N, color="k", ls=":", lw=0.8)
    left.axhline(block.mu_d * N, color="k", ls=":", lw=0.8)
    left.annotate("μs N", (0.02, block.mu_s * N + 0.05))
    left.annotate("μd N", (0.02, block.mu_d * N + 0.05))
    left.set(xlabel="t [s]", ylabel="friction force on the block [N]", title="friction: μs N at break-away, then μd N")
    left.legend(fontsize=8)
    right.plot(run.t, block.velocity(run.t), "k:", lw=1, label="closed form")
    right.set(xlabel="t [s]", ylabel="velocity [m/s]", title="velocity")
    right.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "pushed_block"))


if __name__ == "__main__":
    main()
