"""Where a found tower's step goes: each part of the compiled Moreau–Jean step timed alone, found
contacts against the same tower declared by hand, in one process.

    python benchmarks/bench_step_parts.py [--boxes 5] [--rounds 5] [--reps 20000] [--quick]

The tower of benchmarks/bench_shapes.py (declared, found) runs 1000 steps to its rest, then each part of the step at that state is repeated --reps times in a
compiled loop of its own (numba; CPU time per call, median of --rounds, the scenes alternated):
`begin` (free velocity, broad phase, kinematics, active set), `broad` (the broad phase alone:
broad_candidates on its kept list, built by the first call — the tower at rest never rebuilds
it; the declared tower's step runs none — too few disk pairs — so its column is the test alone),
`solve` (assemble and the two-coefficient Lemke solve),
`finish` (end velocity and state, the records of the contacts with a column — the candidates so
far, moreau_jean_loop.new_records —, rows cycled over a window of 4000 steps as a run writes them,
impacts, memory), `finish 1 row` (the same on one row: the records' memory
traffic is the difference) and `after` (the rest's ring), then the whole loop for 4000 steps from
that state (`run`, per step; the rest is not repeated). Prints the parts side by side and their
differences from the declared tower. Needs numba (its harness compiles in ~10 s, not cached:
no test runs it). --quick: 2 boxes, 2000 reps, one round.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_shapes  # noqa: E402

from nonsmooth_rod.integrators import moreau_jean as mj  # noqa: E402
from nonsmooth_rod.integrators import moreau_jean_loop as L  # noqa: E402
from nonsmooth_rod.integrators.moreau_jean_records import Grid  # noqa: E402
from nonsmooth_rod.integrators.scene_plans import scene_plan  # noqa: E402

WARM_STEPS, RUN_STEPS, FINISH_ROWS = 1000, 4000, 4000


def _harness():
    """The compiled loops that repeat one part of the step (numba's njit, not cached)."""
    import numba

    @numba.njit
    def begin(reps, params, f, m, w, o, s, k):
        na = 0
        for _ in range(reps):
            na = L.begin_arrays(params, o.q[k], o.v[k], f, m.minv, m.contacts, m.contact_index, m.disks, m.disk_body,
                                m.pair_keys, m.pair_contact, m.joints, w.joint_buffer, w.gaps, w.drifts, w.hn, w.ht,
                                w.active, w.was_closed, w.v_free, w.a_free, w.candidate, s.floats, s.kept,
                                s.kept_pose, k, o)
        return na

    @numba.njit
    def broad(reps, params, f, m, w, o, s, k):
        h = params[L.P_H]
        for _ in range(reps):
            L.broad_candidates(h, params[L.P_GAMMA], o.q[k], o.v[k], m.disks, m.disk_body, m.pair_keys,
                               m.pair_contact, m.contacts, m.contact_index, w.was_closed, w.candidate, s.floats,
                               s.kept, s.kept_pose, o.column)
        return 0

    @numba.njit
    def solve(reps, params, iparams, na, m, w, o, s, k):
        p, u, states = L.step_impulses(na, s.floats, s.states)
        status = 0
        for _ in range(reps):
            status = L.solve_arrays(iparams[L.I_SOLVER], k, params, iparams, na, o.q[k], o.v[k], m.minv, m.contacts,
                                    m.contact_index, m.joints, w.joint_buffer, w.gaps, w.hn, w.ht, w.active,
                                    w.was_closed, w.grazing, w.slip_sign, w.v_free, o.p_normal, o.p_tangent,
                                    o.column, o.counters, s, p, u, states)
        return status

    @numba.njit
    def finish(reps, rows, params, iparams, na, m, w, o, s, k):
        p, u, states = L.step_impulses(na, s.floats, s.states)
        qk, vk = o.q[k].copy(), o.v[k].copy()
        for r in range(reps):
            L.finish_arrays(r % rows, params, iparams, na, p, u, states, qk, vk, m.minv, m.contacts,
                            m.contact_index, m.pair_keys, m.joints, w.joint_buffer, w.gaps, w.drifts, w.hn, w.ht,
                            w.active, w.was_closed, w.grazing, w.slip_sign, w.v_free, w.a_free, w.candidate, o,
                            s.kept)
        return 0

    @numba.njit
    def after(reps, w, o, ring, before, k):
        for _ in range(reps):
            L._after_step(k, 0, k + RUN_STEPS, w, o, ring, before)
        return 0

    return begin, broad, solve, finish, after


def at_rest(scene, q0):
    """(model, work, out, params, iparams) after WARM_STEPS steps of the scene from q0 at rest
    (the rest not repeated: each step runs)."""
    grid = Grid.of(1e-3, 0.0, 10.0, None)
    plan = scene_plan(scene)
    model, work, v0 = mj._run_data(plan, q0, np.zeros_like(q0), grid, None)
    window = mj._window(plan, scene.n_dof, len(plan.names), WARM_STEPS + RUN_STEPS + 8, 0)  # the run's columns
    window.seed(q0, v0, 0, None)
    params, iparams = mj.MoreauJean(mj.MoreauJeanOptions(h=1e-3))._parameters(scene, grid, list(plan.names))
    iparams[L.I_TIME_INVARIANT] = 0
    if L.run_steps(0, WARM_STEPS, params, iparams, model, work, window.out, mj.NO_EXTRA_FORCE) != L.RUN_OK:
        raise RuntimeError("the tower did not run")
    return model, work, window.out, params, iparams


def _cpu_us(fn, reps, *args):
    fn(2, *args)  # compiled
    started = time.process_time()
    fn(reps, *args)
    return (time.process_time() - started) / reps * 1e6


def parts(harness, data, reps):
    """{part: µs} of one scene at its rest state (WARM_STEPS)."""
    begin, broad, solve, finish, after = harness
    model, work, out, params, iparams = data
    k = WARM_STEPS
    scratch = L.step_scratch(iparams[L.I_SOLVER], model, 0)
    f = np.empty(model.minv.shape[0])
    L.step_force(k, params, model, out, f)
    ring, before = np.zeros((3, 3, model.contacts.shape[0])), np.zeros((3, len(L.REPEATED_COUNTERS)), dtype=np.int64)
    na = begin(1, params, f, model, work, out, scratch, k)
    row = {"begin": _cpu_us(begin, reps, params, f, model, work, out, scratch, k),
           "broad": _cpu_us(broad, reps, params, f, model, work, out, scratch, k),
           "solve": _cpu_us(solve, reps, params, iparams, na, model, work, out, scratch, k),
           "finish": _cpu_us(finish, reps, FINISH_ROWS, params, iparams, na, model, work, out, scratch, k),
           "finish 1 row": _cpu_us(finish, reps, 1, params, iparams, na, model, work, out, scratch, k),
           "after": _cpu_us(after, reps, work, out, ring, before, k)}
    out[9][L.K_DONE] = k
    started = time.process_time()
    L.run_steps(k, k + RUN_STEPS, params, iparams, model, work, out, mj.NO_EXTRA_FORCE)
    row["run"] = (time.process_time() - started) / RUN_STEPS * 1e6
    return row


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--boxes", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--reps", type=int, default=20000)
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    boxes, rounds, reps = (2, 1, 2000) if args.quick else (args.boxes, args.rounds, args.reps)
    scenes = {"declared": bench_shapes.tower(boxes, False), "found": bench_shapes.tower(boxes, True)}
    data = {name: at_rest(*scene) for name, scene in scenes.items()}
    harness = _harness()
    rows = {name: [] for name in scenes}
    for _ in range(rounds):
        for name in scenes:
            rows[name].append(parts(harness, data[name], reps))
    med = {name: {part: statistics.median(r[part] for r in rs) for part in rs[0]} for name, rs in rows.items()}
    print(f"{boxes} boxes at rest, CPU µs per call (median of {rounds}; run: per step of {RUN_STEPS})")
    print(f"{'part':14s}" + "".join(f"{name:>18s}" for name in scenes) + f"{'found - declared':>18s}")
    for part in med["declared"]:
        print(f"{part:14s}" + "".join(f"{med[name][part]:18.3f}" for name in scenes)
              + f"{med['found'][part] - med['declared'][part]:+18.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
