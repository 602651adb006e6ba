"""Painlevé's sliding rod: where the sliding equations have no solution.

A thin uniform rod (length 1 m, μs = μd = 2) slides on its lower end, launched at −10 m/s at
θ = 30°. Friction lifts the rod towards the band of angles where J/m + a² cos²θ < μd a² cos θ sin θ
(37.4° … 79.2°), in which the sliding equations have no consistent solution (Painlevé's paradox;
possible only for μd > 4/3). The normal force grows without bound as the rod nears the band:
the event-driven reference stops there with status "painleve". Moreau–Jean passes the point
with a tangential impact — a finite impulse without a collision — that stops the slip and
throws the rod off the floor.

    python examples/painleve_rod.py [--out DIR]
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from nonsmooth_rod import toys  # noqa: E402


def slip_velocity(rod, run):
    scene = rod.scene()
    return np.array([scene.kinematics(q, v)[0].H_T @ v for q, v in zip(run.trajectory.q, run.trajectory.v)])


def main(argv=None):
    args = toys.example_parser(__doc__.splitlines()[0]).parse_args(argv)
    rod = toys.PainleveRod()
    band = np.degrees(rod.painleve_band())
    ed = toys.run(rod, "event-driven", 0.16, rtol=1e-10)  # 1e-12 only slows the stiff approach
    print(f"inconsistent band: {band[0]:.4f}° … {band[1]:.4f}°")
    print(f"event-driven: status {ed.status!r} at t = {ed.t[-1]:.6f} s, θ = {np.degrees(ed.trajectory.q[-1, 2]):.6f}°, "
          f"N = {ed.trajectory.normal_force[-1, 0]:.3g} N")
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), constrained_layout=True)
    ax_theta, ax_slip, ax_force, ax_impulse = axes.ravel()
    ax_theta.plot(ed.t, np.degrees(ed.trajectory.q[:, 2]), "k-", lw=2, alpha=0.4, label=f"event-driven ({ed.status})")
    ax_slip.plot(ed.t, slip_velocity(rod, ed), "k-", lw=2, alpha=0.4, label="event-driven")
    ax_force.semilogy(ed.t, ed.trajectory.normal_force[:, 0], "k-", lw=2, alpha=0.4, label="event-driven")
    for h, style in ((1e-3, "--"), (1e-4, "-"), (1e-5, ":")):
        mj = toys.run(rod, "moreau-jean", 0.16, h=h)
        impulse = mj.trajectory.normal_force[:, 0] * h
        k = int(np.argmax(impulse))
        print(f"Moreau-Jean h = {h:g}: impulse {impulse[k]:.4f} N·s in one step at t = {mj.t[k]:.5f} s, "
              f"θ = {np.degrees(mj.trajectory.q[k - 1, 2]):.3f}°, slip {slip_velocity(rod, mj)[k - 1]:+.3f} → "
              f"{slip_velocity(rod, mj)[k]:+.3f} m/s, then {mj.trajectory.modes[k + 1, 0]}")
        ax_theta.plot(mj.t, np.degrees(mj.trajectory.q[:, 2]), style, label=f"Moreau–Jean, h = {h:g}")
        ax_slip.plot(mj.t, slip_velocity(rod, mj), style, label=f"h = {h:g}")
        ax_impulse.semilogy(mj.t[1:], impulse[1:], style, label=f"h = {h:g}: largest {impulse[k]:.3f} N·s")
    ax_theta.axhspan(band[0], band[1], color="tab:red", alpha=0.12, label="no consistent sliding")
    ax_theta.set(xlabel="t [s]", ylabel="θ [°]", title="rod angle", ylim=(25, 90))
    ax_theta.legend(fontsize=8)
    ax_slip.set(xlabel="t [s]", ylabel="slip velocity of the end [m/s]", title="slip stops at the tangential impact")
    ax_slip.legend(fontsize=8)
    ax_force.set(xlabel="t [s]", ylabel="N [N]", title="event-driven: N → ∞ at the band edge")
    ax_impulse.set(xlabel="t [s]", ylabel="normal impulse per step [N·s]",
                   title="Moreau–Jean: one finite impulse, independent of h", ylim=(1e-6, 3))
    ax_impulse.legend(fontsize=8)
    print("wrote", toys.save_figure(fig, args.out, "painleve_rod"))


if __name__ == "__main__":
    main()
