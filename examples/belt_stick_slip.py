"""Stick–slip oscillator: a block on a belt moving at 0.1 m/s, held by a spring (k = 100 N/m).

The block rides the belt (stick) until the spring force reaches μs N, slips with friction μd N
around x_d = μd N/k until its velocity matches the belt again, and sticks: a limit cycle with
stick time 2 y0/v_b and slip time (2π − 2 atan(ω y0/v_b))/ω, y0 = (μs − μd) N/k, ω = √(k/m).
The belt is a `Line` with a surface velocity; the spring is an applied force.

    python examples/belt_stick_slip.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    belt = toys.BeltOscillator(belt_speed=0.1, stiffness=100.0, mu_s=0.6, mu_d=0.4)
    h = 1e-3
    mj = toys.run(belt, "moreau-jean", 2.5, h=h)
    ed = toys.run(belt, "event-driven", 2.5)
    print(f"closed form: first slip {belt.first_slip_time:.6f} s, stick {belt.stick_time:.6f} s, "
          f"slip {belt.slip_time:.6f} s")
    for label, run, unit in (("event-driven", ed, 1.0), (f"Moreau-Jean h = {h:g}", mj, h)):
        phases = toys.stick_slip_phases(run)
        slips = [end - start for mode, start, end in phases[:-1] if mode == "slip"]  # last one cut by t_end
        sticks = [end - start for mode, start, end in phases[1:-1] if mode == "stick"]
        name = "s" if unit == 1.0 else "h"
        print(f"{label}: first slip error {(phases[1][1] - belt.first_slip_time) / unit:+.2e} {name}, "
              f"slip errors {', '.join(f'{(d - belt.slip_time) / unit:+.2e}' for d in slips)} {name}, "
              f"stick errors {', '.join(f'{(d - belt.stick_time) / unit:+.2e}' for d in sticks)} {name}")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    left.plot(mj.t, mj.trajectory.q[:, 0], label=f"Moreau–Jean, h = {h:g} s")
    left.plot(ed.t, ed.trajectory.q[:, 0], "--", label="event-driven")
    for level, text in ((belt.slip_onset_position, "μs N / k"), (belt.restick_position, "(2μd − μs) N / k")):
        left.axhline(level, color="k", ls=":", lw=0.8)
        left.annotate(text, (0.02, level + 0.001))
    left.set(xlabel="t [s]", ylabel="block position x [m]", title="stick (rides the belt) and slip")
    left.legend(fontsize=8)
    x, xdot = belt.limit_cycle()
    right.plot(x, xdot, "k-", lw=2.5, alpha=0.3, label="closed-form limit cycle")
    right.plot(mj.trajectory.q[:, 0], mj.trajectory.v[:, 0], lw=0.9, label="Moreau–Jean")
    right.plot(ed.trajectory.q[:, 0], ed.trajectory.v[:, 0], "--", lw=0.9, label="event-driven")
    right.axhline(belt.belt_speed, color="tab:red", ls=":", lw=0.8, label="belt speed")
    right.set(xlabel="x [m]", ylabel="ẋ [m/s]", title="phase plane")
    right.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "belt_stick_slip"))


if __name__ == "__main__":
    main()
