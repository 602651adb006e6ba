"""Moreau–Jean time-stepping (θ-method) for planar rigid bodies with unilateral frictional contact.

Per step of size h, from (q_k, v_k):

    v_free  = v_k + h M⁻¹ f(t_k + θh, q_k, v_k)
    active  = contacts whose predicted gap g + γ h u_N closes (γ = ½ by default)
    u       = W p + q_step,  W = H M⁻¹ Hᵀ,  q_step = (H v_free + e u_N^k for the normal rows)
    p       from the exact two-coefficient law (onestep.solve_two_coefficient, any solver)
    v_{k+1} = v_free + M⁻¹ Hᵀ p
    q_{k+1} = q_k + h ((1 − θ) v_k + θ v_{k+1})

Impacts need no special case: a contact that closes within a step gets the impulse that makes
u_N⁺ + e u_N⁻ ≥ 0 ⊥ p_N ≥ 0 hold at the end of the step. The scheme is first order on
nonsmooth solutions and, with e = 0 and θ = ½, dissipative (energy never grows).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..model.scene import Scene
from . import fast_moreau_jean
from ..solvers.two_coefficient import solve_two_coefficient
from ..results import Event, Impact, SimulationResult, Trajectory, phases_from_intervals
from ..solvers import available_solvers
from ..solvers.problem import SolverError
from ..validation import InputError, require_in_range, require_positive

# Gaps below a picometre count as touching: a contact placed exactly on a line computes a gap
# of a few ulps either side of zero, and must not be left out of the step for that.
ACTIVATION_ROUNDOFF = 1e-12
# A gap below this many ulps of the largest coordinate is round-off: not closed (_gap_to_close).
GAP_ROUNDOFF_ULPS = 64.0
GAP_ROUNDOFF = GAP_ROUNDOFF_ULPS * float(np.finfo(float).eps)
STATE_CODES = {"open": 0, "stick": 1, "slip+": 2, "slip-": 3}
STATE_NAMES = ("open", "stick", "slip+", "slip-")


@dataclass
class MoreauJeanOptions:
    """Step size, θ of the θ-method, contact activation and the one-step solver."""

    h: float = 1e-4
    theta: float = 0.5
    activation_gamma: float = 0.5  # a contact enters the step when g + γ h u_N ≤ 0
    solver: str = "lemke"
    solver_options: dict = field(default_factory=dict)
    stop_at_impact: str | None = None  # name of a contact whose first impact ends the run
    min_phase: float | None = None  # phases shorter than this are merged (default 2h)
    allow_energy_gain: bool = False  # θ < ½ amplifies energy; refused unless asked for
    fast: bool = True  # use the compiled loop when the scene and solver allow it

    def __post_init__(self):
        require_positive("h (step size)", self.h)
        require_in_range("theta", self.theta, 0.0, 1.0)
        require_in_range("activation gamma", self.activation_gamma, 0.0, 1.0)
        if self.theta < 0.5 and not self.allow_energy_gain:
            raise InputError(
                f"theta = {self.theta:g} < 0.5 makes Moreau–Jean gain energy; use theta in [0.5, 1] "
                "(or allow_energy_gain=True to study it)"
            )
        if self.solver not in available_solvers():
            raise InputError(f"unknown solver '{self.solver}'; choose from: {', '.join(available_solvers())}")
        if self.min_phase is None:
            self.min_phase = 2 * self.h
        elif self.min_phase < 0:
            raise InputError(f"min_phase must be non-negative, got {self.min_phase!r}")


class MoreauJean:
    """The Moreau–Jean one-step integrator over a Scene."""

    name = "moreau-jean"

    def __init__(self, options: MoreauJeanOptions | None = None):
        self.options = options or MoreauJeanOptions()

    def run(self, scene: Scene, q0, v0, t_end: float) -> SimulationResult:
        require_positive("t_end", t_end)
        opts = self.options
        h, th = opts.h, opts.theta
        n_steps = max(1, int(math.ceil(t_end / h - 1e-9)))
        n_dof, nc = scene.n_dof, len(scene.contacts)
        names = [c.name for c in scene.contacts]
        minv = scene.inverse_mass_diagonal
        mu_s = np.array([c.law.friction.mu_s for c in scene.contacts])
        mu_d = np.array([c.law.friction.mu_d for c in scene.contacts])
        rest = np.array([c.law.impact.restitution for c in scene.contacts])
        stop_index = names.index(opts.stop_at_impact) if opts.stop_at_impact in names else None
        if opts.fast and fast_moreau_jean.eligible(scene, opts.solver):
            return self._run_compiled(scene, q0, v0, n_steps, stop_index, names, t_end)

        q = np.empty((n_steps + 1, n_dof))
        v = np.empty((n_steps + 1, n_dof))
        pN = np.zeros((n_steps, nc))
        pT = np.zeros((n_steps, nc))
        states = np.zeros((n_steps, nc), dtype=np.int8)
        q[0], v[0] = q0, v0
        slip_sign = np.zeros(nc)
        was_closed = np.zeros(nc, dtype=bool)
        events: list[Event] = []
        impacts: list[Impact] = []
        status, message = "ok", f"reached t_end = {t_end:g} s"
        solves = iterations = inconsistent = 0
        t_stop = None
        wall = time.process_time()
        k = 0
        for k in range(n_steps):
            t = k * h
            qk, vk = q[k], v[k]
            kin = scene.kinematics(qk, vk)
            f = scene.force(t + th * h, qk, vk)
            v_free = vk + h * minv * f
            # A contact enters the step when its predicted gap closes. A contact that acted in
            # the previous step stays while its predicted gap is within the gap change one step
            # of its own acceleration can cause (h² |g̈|): the velocity-level law lets a resting
            # contact's gap wander by that much, and dropping it for one step would insert a
            # spurious free-flight step (and a wrong slip guess) into a rolling phase.
            active = []
            for i, c in enumerate(kin):
                predicted = c.gap + opts.activation_gamma * h * float(c.H_N @ vk)
                margin = ACTIVATION_ROUNDOFF
                if was_closed[i]:
                    margin = max(margin, h * h * (abs(c.drift_N) + abs(float(c.H_N @ (minv * f)))))
                if predicted <= margin:
                    active.append(i)
            if active:
                position_scale = max(1.0, max(map(abs, qk.tolist())))  # plain floats: per step
                H = np.empty((2 * len(active), n_dof))
                q_step = np.empty(2 * len(active))
                guess = np.empty(len(active))
                closing = np.zeros(len(active))
                for j, i in enumerate(active):
                    c = kin[i]
                    H[2 * j], H[2 * j + 1] = c.H_N, c.H_T
                    if was_closed[i]:
                        # A persistent contact may close an open gap, not only keep u_N ≥ 0:
                        # the Jacobian turns with the body within the step, so a purely
                        # velocity-level law lets the gap creep open by O(h) per unit time (then
                        # the contact drops out and re-impacts). Asking u_N ≥ −g/h for g > 0
                        # removes the creep; a penetration (g < 0) is not pushed out, which
                        # would inject energy after every impact.
                        closing[j] = _gap_to_close(c.gap, position_scale) / h
                        q_step[2 * j] = float(c.H_N @ v_free) + closing[j]
                    else:
                        u_N_k = float(c.H_N @ vk)
                        q_step[2 * j] = float(c.H_N @ v_free) + rest[i] * min(u_N_k, 0.0)
                    q_step[2 * j + 1] = float(c.H_T @ v_free) - c.surface_velocity
                    if was_closed[i]:
                        guess[j] = slip_sign[i]
                    else:  # a contact that closes now slides the way it arrives
                        u_T_k = float(c.H_T @ vk) - c.surface_velocity
                        guess[j] = 0.0 if abs(u_T_k) < 1e-12 else math.copysign(1.0, u_T_k)
                W = H @ (minv[:, None] * H.T)
                a_idx = np.array(active)
                try:
                    res = solve_two_coefficient(W, q_step, mu_s[a_idx], mu_d[a_idx], guess,
                                                opts.solver, opts.solver_options, closing=closing)
                except SolverError as err:
                    state_txt = ", ".join(f"{names[i]}:{STATE_NAMES[states[k - 1, i]] if k else 'initial'}"
                                          for i in range(nc))
                    status = "failed"
                    message = str(err.with_context(
                        f"step {k}, t = {t:.9g} s, contact states {state_txt}, q = {np.array2string(qk, precision=6)}"))
                    events.append(Event(t, "solver-failure", "", {"message": message}))
                    break
                solves += res.solves
                iterations += res.iterations
                inconsistent += not res.consistent
                v_next = v_free + minv * (H.T @ res.p)
                for j, i in enumerate(active):
                    pN[k, i], pT[k, i] = res.p[2 * j], res.p[2 * j + 1]
                    states[k, i] = STATE_CODES[res.states[j]]
                    slip_sign[i] = {"slip+": 1.0, "slip-": -1.0}.get(res.states[j], 0.0)
            else:
                v_next = v_free
            closed_now = pN[k] > 0.0
            v[k + 1] = v_next
            q[k + 1] = qk + h * ((1.0 - th) * vk + th * v_next)
            new_impacts = np.nonzero(closed_now & ~was_closed)[0]
            for i in new_impacts:
                u_before = float(kin[i].H_N @ vk)
                if u_before < -1e-9:  # a closing contact, not a resting one re-entering
                    t_hit = self._crossing_time(scene, kin[i], f, vk, t, h)
                    v_hit = vk + (t_hit - t) * minv * f
                    q_hit = qk + (t_hit - t) * vk
                    impacts.append(Impact(t_hit, names[i], q_hit, v_hit, v_next.copy(),
                                          pN[k].copy(), pT[k].copy()))
                    events.append(Event(t_hit, "impact", names[i], {"step": k}))
                    if stop_index == i and t_stop is None:
                        t_stop = t_hit
            was_closed = closed_now
            if not (np.all(np.isfinite(v[k + 1])) and np.all(np.isfinite(q[k + 1]))):
                status, message = "failed", f"non-finite state at step {k + 1}, t = {(k + 1) * h:.9g} s"
                break
            if t_stop is not None:
                status, message = "ok", f"stopped at the impact of {opts.stop_at_impact}"
                break
        n_done = k + 1 if status == "ok" else k
        cpu = time.process_time() - wall
        return self._result(scene, q, v, pN, pT, states, n_done, h, names, events, impacts,
                            status, message, cpu, t_stop,
                            {"solves": solves, "solver_iterations": iterations,
                             "inconsistent_steps": inconsistent, "h": h, "theta": th,
                             "solver": opts.solver, "compiled": False})

    @staticmethod
    def _crossing_time(scene, kin, f, vk, t, h) -> float:
        """When the contact's gap crossed zero: the root of g + u τ + ½ a τ² nearest the step.

        The contact may enter the problem a little before (predicted gap) or after (closing in
        the second half of the previous step) the geometric crossing, so τ ∈ [−h, 2h].
        """
        g = kin.gap
        u = float(kin.H_N @ vk)
        a = float(kin.H_N @ (scene.inverse_mass_diagonal * f)) + kin.drift_N
        roots = []
        if abs(a) > 1e-14:
            disc = u * u - 2.0 * a * g
            if disc >= 0.0:
                sq = math.sqrt(disc)
                roots = [(-u - sq) / a, (-u + sq) / a]
        elif u != 0.0:
            roots = [-g / u]
        roots = [r for r in roots if -h <= r <= 2 * h]
        if not roots:
            return t
        return t + min(roots, key=abs)

    def _run_compiled(self, scene, q0, v0, n_steps, stop_index, names, t_end) -> SimulationResult:
        opts = self.options
        wall = time.process_time()
        (q, v, pN, pT, states, n_done, code, fail_step, impact_t, impact_step, impact_contact, t_stop,
         solves, inconsistent) = fast_moreau_jean.run_compiled(scene, q0, v0, opts.h, opts.theta, opts.activation_gamma,
                                                       n_steps, -1 if stop_index is None else stop_index)
        cpu = time.process_time() - wall
        h = opts.h
        events, impacts = [], []
        minv = scene.inverse_mass_diagonal
        f = scene.force(0.0, q[0], v[0])
        for t_hit, k, i in zip(impact_t, impact_step, impact_contact):
            k, i, t_hit = int(k), int(i), float(t_hit)
            if k >= n_done:
                continue
            v_hit = v[k] + (t_hit - k * h) * minv * f
            q_hit = q[k] + (t_hit - k * h) * v[k]
            impacts.append(Impact(t_hit, names[i], q_hit, v_hit, v[k + 1].copy(), pN[k].copy(), pT[k].copy()))
            events.append(Event(t_hit, "impact", names[i], {"step": k}))
        status, message = "ok", f"reached t_end = {t_end:g} s"
        t_stop = None if math.isnan(t_stop) else float(t_stop)
        if t_stop is not None:
            message = f"stopped at the impact of {opts.stop_at_impact}"
        if code == fast_moreau_jean.RUN_SOLVER_FAILED:
            k = int(fail_step)
            state_txt = ", ".join(f"{names[i]}:{STATE_NAMES[states[k - 1, i]] if k else 'initial'}"
                                  for i in range(len(names)))
            status = "failed"
            message = (f"lemke: no valid solution of the step problem (step {k}, t = {k * h:.9g} s, "
                       f"contact states {state_txt}, q = {np.array2string(q[k], precision=6)})")
            events.append(Event(k * h, "solver-failure", "", {"message": message}))
        elif code == fast_moreau_jean.RUN_NONFINITE:
            status, message = "failed", f"non-finite state at step {fail_step}, t = {fail_step * h:.9g} s"
        return self._result(scene, q, v, pN, pT, states, int(n_done), h, names, events, impacts, status,
                            message, cpu, t_stop,
                            {"solves": int(solves), "inconsistent_steps": int(inconsistent), "h": h,
                             "theta": opts.theta, "solver": opts.solver, "compiled": True})

    def _result(self, scene, q, v, pN, pT, states, n_done, h, names, events, impacts, status, message,
                cpu, t_stop, stats) -> SimulationResult:
        t = np.arange(n_done + 1) * h
        q, v = q[: n_done + 1], v[: n_done + 1]
        a = np.full_like(v, np.nan)
        a[1:] = np.diff(v, axis=0) / h
        N = np.zeros((n_done + 1, len(names)))
        T = np.zeros_like(N)
        N[1:] = pN[:n_done] / h
        T[1:] = pT[:n_done] / h
        modes = np.empty((n_done + 1, len(names)), dtype=object)
        codes = states[:n_done]
        modes[1:] = np.array(STATE_NAMES, dtype=object)[codes]
        modes[0] = modes[1] if n_done else "open"
        bounds = t.copy()
        if t_stop is not None and n_done >= 1:
            bounds[-1] = max(t_stop, bounds[-2])
        phases = {}
        if n_done:
            for ci, name in enumerate(names):
                phases[name] = phases_from_intervals(bounds, list(modes[1:, ci]), self.options.min_phase)
        traj = Trajectory(t, q, v, a, N, T, modes)
        stats = dict(stats, steps=n_done)
        return SimulationResult(self.name, status, message, traj, names, events, impacts, phases,
                                steps=n_done, cpu_time_s=cpu, stats=stats)


def _gap_to_close(gap: float, position_scale: float) -> float:
    """The gap a persistent contact is asked to close in one step: none if it is position round-off.

    A gap of a few ulps of the positions is not a gap; closing it within the step asks the
    contact for a velocity round-off/h that the body's other contacts cannot all follow (q_step
    leaves the range of W), so a statically indeterminate body at rest would have to slip.
    """
    return gap if gap > GAP_ROUNDOFF * position_scale else 0.0
