"""Bouncing ball: impacts, their accumulation (Zeno) point, and rest on the floor.

A ball dropped from 1 m with restitution e = 0.5 hits the floor at t_1 = √(2 h0/g), then after
flights 2 e^k v_1/g; the impacts accumulate at t_∞ = t_1 (1 + e)/(1 − e) = 1.3546 s.
Moreau–Jean passes the accumulation point and leaves the ball resting; the event-driven
reference locates every impact and stops there with status "zeno".

    python examples/bouncing_ball.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    ball = toys.BouncingBall(drop_height=1.0, restitution=0.5)
    h = 1e-3
    mj = toys.run(ball, "moreau-jean", 1.6, h=h)
    ed = toys.run(ball, "event-driven", 1.6, output_dt=1e-3)

    mj_times = np.array([imp.t for imp in mj.impacts])
    exact = ball.impact_times(len(mj_times))
    rest = toys.rest_time(mj, ball)
    print(f"Zeno time t_inf = {ball.zeno_time:.6f} s")
    print(f"event-driven: {len(ed.impacts)} impacts, status {ed.status!r}, "
          f"max impact-time error {max(abs(i.t - t) for i, t in zip(ed.impacts, ball.impact_times(len(ed.impacts)))):.1e} s, "
          f"accumulation at {ed.events[-1].detail.get('t_accumulation', float('nan')):.9f} s")
    print(f"Moreau-Jean h = {h:g}: {len(mj_times)} impacts, max flight error "
          f"{np.max(np.abs(np.diff(mj_times) - np.diff(exact))) / h:.2f} h, at rest from {rest:.4f} s "
          f"({(rest - ball.zeno_time) / h:+.1f} h), deepest penetration {-toys.ball_height(mj, ball).min():.2e} m")

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, constrained_layout=True)
    top.plot(mj.t, toys.ball_height(mj, ball), label=f"Moreau–Jean, h = {h:g} s")
    top.plot(ed.t, toys.ball_height(ed, ball), "--", label=f"event-driven ({ed.status})")
    for t in ball.impact_times(12):
        top.axvline(t, color="0.85", lw=0.8, zorder=0)
    top.axvline(ball.zeno_time, color="k", ls=":", label="accumulation t∞")
    top.set(ylabel="height of the lowest point [m]", title="Bouncing ball, e = 0.5")
    top.legend()
    bottom.plot(mj.t, mj.trajectory.v[:, 1], label="Moreau–Jean")
    bottom.plot(ed.t, ed.trajectory.v[:, 1], "--", label="event-driven")
    bottom.axvline(ball.zeno_time, color="k", ls=":")
    bottom.set(xlabel="t [s]", ylabel="vertical velocity [m/s]")
    print("wrote", toys.save_figure(fig, args.out, "bouncing_ball"))


if __name__ == "__main__":
    main()
