"""The block sliding off a table's end (examples/scenes/box_off_table.toml, contacts found from
its shapes): Moreau–Jean's phase boundaries against the event-driven reference's located events.

    python benchmarks/bench_box_off_table.py [--quick] [--out DIR]

The reference (event-driven, rtol = atol = 1e-12) locates: the front corner leaving the table's
top (its foot passing the table's end: a `leave-feature` event, closed form from the sliding
deceleration μd g), the table's end taking the load under the block's bottom edge at that
instant, the rear corner lifting (the block's centre at −μd H/2, closed form), the block leaving
the table's edge after pivoting and sliding on it, and its landing on the floor. For each step h,
Moreau–Jean's boundaries (its phase tables, its first impact) minus the reference's, in units
of h. Writes DIR/box_off_table.csv and prints a markdown table.
--quick: h = 1e-4 up to just after the block leaves the edge (a test runs it); the full run
adds h = 1e-5 up to the landing (~30 s of CPU for it alone).
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from nonsmooth_rod.io import write_csv
from nonsmooth_rod.scenefile import load_scene, simulate_scene

SCENE = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "box_off_table.toml"
RUNS = {"quick": ((1e-4, 0.55),), "full": ((1e-4, 0.8), (1e-5, 0.8))}  # (h, t_end)
FRONT, REAR, EDGE = "block.v1/table.side+", "block.v0/table.side+", "table.b/block.e0"
W, H, MU_D, G = 0.4, 0.2, 0.2, 9.81  # the scene's block, its law with the table, gravity


def boundaries(result) -> dict:
    """The located boundaries (s) of a run, by what happens; NaN where it did not happen."""
    phases = {name: [(p.mode, p.t_start) for p in result.phases[name]] for name in (FRONT, REAR, EDGE)}

    def start(name, k):
        return phases[name][k][1] if len(phases[name]) > k else math.nan
    landing = next((i.t for i in result.impacts if i.contact.endswith("/floor")), math.nan)
    return {"front corner leaves the top": start(FRONT, 1), "table's end takes the load": start(EDGE, 1),
            "rear corner lifts": start(REAR, 1), "block leaves the edge": start(EDGE, 2),
            "block lands on the floor": landing}


def closed_forms(sf) -> dict:
    """The sliding phase's boundaries: the centre, decelerating at μd g from x0, v0, reaches −W/2
    (the front corner at the table's end) and −μd H/2 (the moments about the table's end)."""
    x0, v0 = float(sf.q0[0]), float(sf.v0[0])

    def reaches(x):
        return (v0 - math.sqrt(v0**2 - 2 * MU_D * G * (x - x0))) / (MU_D * G)
    return {"front corner leaves the top": reaches(-W / 2), "rear corner lifts": reaches(-MU_D * H / 2)}


def compare(quick: bool) -> list[dict]:
    rows = []
    for h, t_end in RUNS["quick" if quick else "full"]:
        reference = simulate_scene(load_scene(SCENE, ["simulation.method=event-driven", f"simulation.t_end={t_end}",
                                                      "simulation.event-driven.rtol=1e-12",
                                                      "simulation.event-driven.atol=1e-12"]))
        stepped = simulate_scene(load_scene(SCENE, [f"simulation.t_end={t_end}", f"simulation.moreau-jean.h={h}"]))
        assert reference.status == "ok" and stepped.status == "ok", (reference.message, stepped.message)
        ref, mj = boundaries(reference), boundaries(stepped)
        exact = closed_forms(load_scene(SCENE))
        for what, t_ref in ref.items():
            if math.isnan(t_ref):
                continue  # beyond this run's end
            rows.append({"h": h, "boundary": what, "event_driven_s": t_ref, "moreau_jean_s": mj[what],
                         "error_in_h": (mj[what] - t_ref) / h,
                         "closed_form_s": exact.get(what, math.nan)})
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default="benchmark")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = compare(args.quick)
    columns = ("h", "boundary", "event_driven_s", "moreau_jean_s", "error_in_h", "closed_form_s")
    write_csv(out / "box_off_table.csv", {c: [r[c] for r in rows] for c in columns}, columns)
    print("| h (s) | boundary | event-driven (s) | closed form (s) | Moreau–Jean (s) | error / h |\n"
          "|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['h']:g} | {r['boundary']} | {r['event_driven_s']:.9f} | {r['closed_form_s']:.9f} | "
              f"{r['moreau_jean_s']:.6f} | {r['error_in_h']:+.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
