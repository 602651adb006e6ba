"""`nonsmooth-rod benchmark`: the work–precision chart and the stability study (study.py)."""
from __future__ import annotations

import argparse
import time

from ..validation import InputError

DEFAULT_METHODS = "event-driven,moreau-jean,hybrid,regularized,switched"

DESCRIPTION = """\
Run every method over a range of its accuracy knob on the paper's cases and measure it against
the event-driven solution at rtol 1e-12. Writes DIR/work_precision.png (CPU time against the
impact-time error and against max |x_O error|), DIR/work_precision.csv (every run:
method,setting,case,knob,cpu_s,work,impact_error_s,x_O_error_m,phases_ok,status),
DIR/stability.md and DIR/stability.csv (finished or not, why not, cost; with the bistable-start
map of case 2, the ε study of regularised friction, the switched formulation at a reversal,
Painlevé/Zeno and Moreau–Jean's θ). Every run has a wall-clock limit, at most --jobs at once.
The full study takes about 4 minutes on 2 cores; --quick about 10 s."""


def register(subparsers) -> None:
    from .options import integer as _int, number as _float

    p = subparsers.add_parser("benchmark", help="work–precision chart and stability study of every method",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cases", default="1,2,3", help="paper cases, comma-separated (default 1,2,3)")
    p.add_argument("--methods", default=DEFAULT_METHODS, help="methods, comma-separated (default: all five)")
    p.add_argument("--quick", action="store_true", help="a few points per method (about 10 s)")
    p.add_argument("--out", default="benchmark", help="output folder (default ./benchmark)")
    p.add_argument("--time-limit", type=_float, default=None,
                   help="wall-clock seconds per run (default 40, quick 10)")
    p.add_argument("--jobs", type=_int, default=2, help="runs at once, each in its own process (default 2)")
    p.add_argument("--no-extras", action="store_true",
                   help="only the sweep: skip the bistable map, ε study, switched and Painlevé/Zeno/θ sections")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(handler=cmd_benchmark)


def _parse_list(text: str, what: str, convert=str) -> list:
    items = [x.strip() for x in text.split(",") if x.strip()]
    if not items:
        raise InputError(f"--{what} is empty")
    try:
        return [convert(x) for x in items]
    except ValueError:
        raise InputError(f"--{what}: not a list of {convert.__name__}s: {text!r}") from None


def cmd_benchmark(args) -> int:
    from pathlib import Path

    from ..rod import study
    from ..io import provenance, write_csv, write_json, write_text

    cases = _parse_list(args.cases, "cases", int)
    methods = _parse_list(args.methods, "methods")
    specs = study.sweep_specs(cases, methods, quick=args.quick)
    time_limit = args.time_limit or (study.QUICK_TIME_LIMIT if args.quick else study.FULL_TIME_LIMIT)
    if time_limit <= 0:
        raise InputError(f"--time-limit must be positive, got {time_limit:g}")
    if args.jobs < 1:
        raise InputError(f"--jobs must be at least 1, got {args.jobs}")
    out = Path(args.out)
    say = (lambda *a: None) if args.quiet else (lambda *a: print(*a, flush=True))
    wall = time.perf_counter()
    refs = {c: study.reference(c) for c in cases}
    for c, ref in refs.items():
        say(f"reference case {c}: impact at {ref.t_impact:.6f} s, phases "
            + ", ".join(f"{p.mode} until {p.t_end:.6f}" for p in ref.phases))
    done = [0]

    def progress(r):
        done[0] += 1
        say(f"[{done[0]:3d}/{len(specs)}] {r['method']:<12} {r['setting']:<16} case {r['case']} {r['knob']:<14} "
            f"{r['status']:<18} cpu {r['cpu_s']:8.3f} s  impact err {r['impact_error_s']:.2e} s")

    records = study.run_specs(specs, refs, time_limit, workers=args.jobs, progress=progress)
    rows = study.stability_records(records, refs)
    write_csv(out / "work_precision.csv", study.work_precision_table(records), study.CSV_COLUMNS)
    # CSV has no place for metadata: where the tables came from goes next to them
    write_json(out / "provenance.json", {"files": ["work_precision.csv", "stability.csv"], "cases": cases,
                                         "methods": methods, "quick": args.quick, "provenance": provenance()})
    write_csv(out / "stability.csv", study.stability_table(rows), study.STABILITY_COLUMNS)
    study.plot_work_precision(records, out / "work_precision.png")
    extras = []
    if not args.no_extras:
        say("bistable start map, ε study, switched formulation, Painlevé/Zeno, θ ...")
        if args.quick:
            bm = study.bistable_map(epsilons=(1e-3, 1e-5), tolerances=(1e-3, 1e-7), time_limit=time_limit)
            es = study.epsilon_study(epsilons=(1e-3, 1e-4), ode_methods=("RK45",))
            sw = study.switched_study(h_values=(1e-3,), adaptive=())
        else:
            bm = study.bistable_map(time_limit=time_limit)
            es = study.epsilon_study(epsilons=(1e-2, 1e-3, 1e-4, 1e-5))
            sw = study.switched_study(h_values=(1e-3, 1e-4), adaptive=("RK45", "LSODA"), time_limit=time_limit)
        write_csv(out / "bistable_map.csv", {k: [r[k] for r in bm] for k in bm[0]})
        extras = [study.bistable_markdown(bm), study.epsilon_markdown(es), study.switched_markdown(sw),
                  study.failure_markdown(study.painleve_and_zeno(), study.theta_energy())]
    command = "nonsmooth-rod benchmark" + (" --quick" if args.quick else "") + \
        (f" --cases {args.cases}" if args.cases != "1,2,3" else "") + \
        (f" --methods {args.methods}" if args.methods != DEFAULT_METHODS else "")
    write_text(out / "stability.md", study.stability_markdown(rows, extras, command))
    n_right = sum(r["right"] for r in rows)
    say(f"{len(rows)} runs ({n_right} right answers) in {time.perf_counter() - wall:.1f} s; files in {out}/: "
        "work_precision.png, work_precision.csv, stability.md, stability.csv"
        + ("" if args.no_extras else ", bistable_map.csv"))
    return 0

