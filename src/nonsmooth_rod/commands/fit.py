"""`nonsmooth-rod fit SCENE.toml --measured FILE --free PATH[=LO:HI] ...`: scene keys from measurements."""
from __future__ import annotations

import argparse
import sys

from .options import EXIT_OK, EXIT_RUN_FAILED, add_output_options, escape

DESCRIPTION = """\
Estimate scene keys (typically a contact's mu_s, mu_d, restitution) from measured events and/or
a measured trajectory, by weighted least squares through the simulation (the event-driven
reference where it handles the scene: event times located inside the step, continuous in the
keys). --measured takes a TOML/JSON file of [[events]] (kind = impact|slip|stick|lift-off,
contact, t, sigma) and/or a CSV (header t,<trajectory.csv columns>; then a row 'sigma,...'; then
samples). Starts from the file's values (--set to change them): start in the measured regime.
Prints estimates, standard uncertainties, correlations, residuals and which keys the data cannot
determine; --json prints that as JSON. Writes fit.json and fit.png into --out. See docs/fitting.md.
  nonsmooth-rod fit paper_rod.toml --measured events.toml --free contacts.A.law.mu_s --free contacts.A.law.mu_d"""


def register(subparsers) -> None:
    p = subparsers.add_parser("fit", help="estimate scene keys (mu_s, mu_d, e, ...) from measurements",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="scene file (.toml, or .json)")
    p.add_argument("--measured", action="append", default=[], metavar="FILE",
                   help="measured events (.toml/.json) or trajectory (.csv); repeatable")
    p.add_argument("--free", action="append", default=[], metavar="PATH[=LO:HI]",
                   help="a scene key to estimate, with optional bounds; repeatable")
    p.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                   help="override a value of the scene file (also the fit's start); repeatable")
    p.add_argument("--posterior", action="store_true",
                   help="also sample the keys' posterior by MCMC (emcee: the 'mcmc' extra); see docs/fitting.md")
    p.add_argument("--walkers", type=int, default=16, metavar="N",
                   help="MCMC walkers (default 16, even, ≥ 2 per key)")
    p.add_argument("--posterior-steps", type=int, default=400, metavar="N",
                   help="MCMC steps per walker (default 400; the first quarter is burn-in)")
    add_output_options(p, default_out="fit", figure="fit.png", force=False)
    p.set_defaults(handler=cmd_fit)


def cmd_fit(args) -> int:
    from ..io import dumps_json, write_json
    from ..studies.fitting import fit
    from .run import writable_folder

    result = fit(args.scene, args.measured, args.free, sets=args.set, posterior=args.posterior, walkers=args.walkers,
                 posterior_steps=args.posterior_steps)
    out_dir = writable_folder(args.out)
    summary = result.as_dict()
    write_json(out_dir / "fit.json", summary)
    if not args.no_plot:
        from ..studies.fit_figure import fit_figure
        from ..studies.map_figure import save

        save(fit_figure(result), out_dir / "fit", ("png",), 110)
    if args.json:
        sys.stdout.write(dumps_json(summary))
    elif not args.quiet:
        _report(result, out_dir)
    return EXIT_OK if result.success else EXIT_RUN_FAILED


def _report(result, out_dir) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console(soft_wrap=True)
    table = Table(title=f"fit ({result.method}; χ² = {result.chi2:.3g}, {result.dof} degrees of freedom)")
    for col in ("key", "estimate", "standard uncertainty", "identifiability"):
        table.add_column(col)
    for p, x, u, v in zip(result.paths, result.estimate, result.uncertainty, result.verdicts):
        table.add_row(p, f"{x:.6g}", "—" if u != u else f"{u:.2g}", escape(v))
    console.print(table)
    res = Table(title="residuals")
    for col in ("quantity", "measured", "fitted", "(fitted − measured)/σ"):
        res.add_column(col)
    for q, m, f, r in list(zip(result.labels, result.measured, result.fitted, result.residuals))[:30]:
        res.add_row(escape(q), f"{m:.6g}", f"{f:.6g}", f"{r:+.2f}")
    console.print(res)
    if result.posterior is not None:
        _report_posterior(console, result.posterior)
    console.print(escape(f"{result.message}; {result.evaluations} simulations; files in {out_dir}/"))


def _report_posterior(console, post) -> None:
    from rich.table import Table

    table = Table(title=f"posterior (MCMC: {post.walkers} walkers × {post.steps} steps, {post.burn} burn-in, "
                        f"acceptance {post.acceptance:.2f})")
    for col in ("key", "mean", "sd", "16 %", "median", "84 %", "autocorrelation [steps]"):
        table.add_column(col)
    for k in post.as_dict()["free"]:
        table.add_row(escape(k["path"]), *(f"{k[c]:.6g}" for c in ("mean", "sd", "q16", "median", "q84")),
                      f"{k['autocorrelation_steps']:.3g}")
    console.print(table)
