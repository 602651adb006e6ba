"""Fuzzing the input surface as a hostile user would: mutants of the example scenes through
`nonsmooth-rod run`, and library calls with bad options.

    python benchmarks/fuzz_inputs.py                # 3000 mutants, in-process, + 40 subprocess runs
    python benchmarks/fuzz_inputs.py --quick        # the test suite's battery (tests/test_fuzz_inputs.py)
    python benchmarks/fuzz_inputs.py --mutants 500 --seed 7

Every outcome must be one of:
  * a clean refusal: exit status 2 and exactly one line on stderr, "nonsmooth-rod: error: ...";
  * a plausible run: exit status 0 (status ok or stopped) or 1 (the run ended badly and says
    so in one line), a trajectory of finite numbers whose last time is t_end unless the run
    stopped early, nothing else on stderr (no warnings);
and never a traceback, a hang (each mutant has a wall-clock bound) or a wrong "ok".
Mutants run with t_end ≤ T_END_CAP (unless the mutation is of t_end) and a regularised run
with a time_limit, so that a battery stays in seconds per hundred mutants.
"""
from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import math
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "examples" / "scenes").glob("*.toml"))
T_END_CAP = 0.05  # s of simulated time per mutant
TIME_LIMIT = 2.0  # s of wall clock for a regularised mutant (its own option)
HANG_SECONDS = 120.0  # a mutant running longer than this is a hang (after the warm-up compiled the engine)

# Values a hostile user might put anywhere: wrong types, edge numbers, huge and malformed things.
HOSTILE = [
    "1e-3", "", "x" * 5000, "name\n", "false", True, False, None, 0, -1, 1, 2, 10**30, 10**400, -(10**20),
    0.0, -0.0, 1e-300, 1e-12, 1e-6, 0.5, 0.999, 1.5, 1e9, 1e300, -1e300, math.nan, math.inf, -math.inf,
    [], [1.0], [1.0, 2.0], [1.0, 2.0, 3.0], ["a", "b"], [[1.0, 2.0]], {}, {"x": 1}, {"tol": "x"},
]
OPTION_VALUES = {  # option name → values worth trying besides HOSTILE
    "h": [1e-4, 1e-3, 0.01, 10.0], "theta": [0.0, 0.4, 1.0], "solver": ["pgs", "enum", "lemke", "magic"],
    "solver_options": [{"tol": 1e-10}, {"max_iter": 5}, {"max_iter": 1e30}, {"tol": math.nan}, [1, 2], {"foo": 1}],
    "allow_energy_gain": ["false", True], "fast": [False, "no"], "ode_method": ["Radau", "Euler"],
    "rtol": [1e-13, 0.1, 10.0], "atol": [1e-20, 1e20], "max_events": [-1, 1, 10**30], "gap_tol": [-1.0, 1e-2],
    "stiffness": [1e300, 1e15, 1.0], "damping": [1e300, 0.0], "epsilon": [1e-30, 10.0], "time_limit": [0.1],
    "min_phase": [-1.0, 0.0, 1e9], "output_dt": [1e-9, 0.01], "max_step": [math.inf, 1e-3],
}
METHOD_OPTIONS = {
    "moreau-jean": ["h", "theta", "solver", "solver_options", "allow_energy_gain", "fast", "min_phase",
                    "activation_gamma"],
    "event-driven": ["rtol", "atol", "ode_method", "max_events", "gap_tol", "velocity_tol", "output_dt",
                     "max_step", "zeno_interval", "impact_solver"],
    "regularized": ["stiffness", "damping", "epsilon", "rtol", "atol", "ode_method", "contact_model",
                    "exponent", "output_dt", "time_limit", "friction_curve", "max_penetration"],
}


# --- the mutant generator (shared with tests/test_fuzz_inputs.py) -----------------------------------

def load_examples() -> list[tuple[str, dict]]:
    from nonsmooth_rod.scenefile import read_data

    return [(path.stem, read_data(path)[0]) for path in SCENES]


def _leaves(node, path=()):
    """Every (path, value) of the tree: table keys and list indices."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        yield path + (key,), value
        yield from _leaves(value, path + (key,))


def _set(data, path, value) -> None:
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


def _delete(data, path) -> None:
    node = data
    for key in path[:-1]:
        node = node[key]
    del node[path[-1]]


def _nested(depth: int) -> str:
    """A placeholder `write_json` expands to a list nested `depth` deep (json.dumps itself
    cannot write one deeper than Python's recursion limit)."""
    return f"@@nested:{depth}@@"


def mutate(rng: np.random.Generator, data: dict) -> tuple[dict, str]:
    """One mutant of a scene's data and what was done to it."""
    data = copy.deepcopy(data)
    kind = rng.choice(["leaf", "leaf", "leaf", "option", "option", "method", "delete", "unknown", "deep"])
    leaves = list(_leaves(data))
    if kind == "option":
        method = str(rng.choice(list(METHOD_OPTIONS)))
        name = str(rng.choice(METHOD_OPTIONS[method]))
        values = OPTION_VALUES.get(name, []) + HOSTILE
        value = copy.deepcopy(values[rng.integers(len(values))])
        data.setdefault("simulation", {})["method"] = method
        for other in METHOD_OPTIONS:  # flat keys of another method would be refused, not fuzzed
            if other != method:
                data["simulation"].pop(other, None)
        data["simulation"].setdefault(method, {})[name] = value
        return data, f"simulation.{method}.{name} = {value!r:.60}"
    if kind == "method":
        method = str(rng.choice(list(METHOD_OPTIONS) + ["switched", 7]))
        data.setdefault("simulation", {})["method"] = method
        return data, f"simulation.method = {method!r}"
    path, _ = leaves[rng.integers(len(leaves))]
    if kind == "delete":
        _delete(data, path)
        return data, f"delete {path}"
    if kind == "unknown":
        target = data if rng.random() < 0.5 else _container(data, path)
        if isinstance(target, dict):
            target["colour"] = "red"
        return data, f"unknown key near {path}"
    if kind == "deep":
        _set(data, path, _nested(int(rng.choice([20, 200, 5000]))))
        return data, f"deeply nested list at {path}"
    value = copy.deepcopy(HOSTILE[rng.integers(len(HOSTILE))])
    _set(data, path, value)
    return data, f"{path} = {value!r:.60}"


def _container(data, path):
    node = data
    for key in path[:-1]:
        node = node[key]
    return node


def bounded(data: dict, description: str) -> dict:
    """The mutant with a short run: t_end capped (unless that is the mutation), a time limit on
    the regularised method."""
    sim = data.get("simulation")
    if isinstance(sim, dict):
        t_end = sim.get("t_end")
        if "t_end" not in description and isinstance(t_end, (int, float)) and not isinstance(t_end, bool):
            sim["t_end"] = min(t_end, T_END_CAP)
        if sim.get("method") == "regularized" and "time_limit" not in description:
            table = sim.get("regularized")
            if isinstance(table, dict):
                table["time_limit"] = TIME_LIMIT
            elif "regularized" not in sim:
                sim["regularized"] = {"time_limit": TIME_LIMIT}
    return data


def mutants(seed: int, count: int) -> list[tuple[str, dict, str]]:
    """`count` mutants (scene name, data, description) from `seed`, the ten examples in turn."""
    rng = np.random.default_rng(seed)
    examples = load_examples()
    out = []
    for k in range(count):
        name, data = examples[k % len(examples)]
        mutant, description = mutate(rng, data)
        out.append((name, bounded(mutant, description), description))
    return out


# --- running one mutant and judging the outcome -------------------------------------------------

class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang


def write_json(data: dict, path: Path) -> None:
    # allow_nan: json writes NaN/Infinity, which the scene reader accepts (and must refuse by key)
    text = json.dumps(data, allow_nan=True)
    for depth in (20, 200, 5000):
        text = text.replace(f'"{_nested(depth)}"', "[" * depth + "1.0" + "]" * depth)
    path.write_text(text, encoding="utf-8")


def run_in_process(scene_path: Path, out_dir: Path) -> tuple[int, str, str]:
    """(exit status, stderr, problem or "") of `nonsmooth-rod run` called in this process."""
    from nonsmooth_rod.cli import main

    stderr = io.StringIO()
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, HANG_SECONDS)
    try:
        with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()), \
                warnings.catch_warnings():
            warnings.simplefilter("always")
            code = main(["run", str(scene_path), "--out", str(out_dir), "--no-plot", "--quiet"])
    except Hang:
        return -1, stderr.getvalue(), f"hang (> {HANG_SECONDS:g} s)"
    except BaseException as err:  # noqa: BLE001 - any escape is the finding
        return -1, stderr.getvalue(), f"traceback: {type(err).__name__}: {str(err)[:200]}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    return code, stderr.getvalue(), ""


def run_subprocess(scene_path: Path, out_dir: Path) -> tuple[int, str, str]:
    command = [sys.executable, "-m", "nonsmooth_rod.cli", "run", str(scene_path), "--out", str(out_dir),
               "--no-plot", "--quiet"]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=HANG_SECONDS)
    except subprocess.TimeoutExpired:
        return -1, "", f"hang (> {HANG_SECONDS:g} s)"
    problem = "traceback" if "Traceback" in done.stderr else ""
    return done.returncode, done.stderr, problem


def judge(code: int, stderr: str, problem: str, out_dir: Path) -> str:
    """"" for a clean refusal or a plausible run, else what is wrong."""
    if problem:
        return problem
    lines = [line for line in stderr.splitlines() if line.strip() and not line.startswith("nonsmooth-rod: compiling")]
    if code == 2:
        if len(lines) == 1 and lines[0].startswith("nonsmooth-rod: error: ") and len(lines[0]) < 2000:
            return ""
        return f"refusal not one short line: {stderr[:300]!r}"
    if code not in (0, 1):
        return f"exit status {code}"
    if len(lines) != (0 if code == 0 else 1):
        return f"stderr of a run: {stderr[:300]!r}"
    return _plausible(out_dir, code)


def _plausible(out_dir: Path, code: int) -> str:
    import pandas as pd

    summary = json.loads((out_dir / "summary.json").read_text())
    table = pd.read_csv(out_dir / "trajectory.csv")
    if table.empty:  # a run that ends before its first sample (Painlevé at t0) must say so
        return "" if code == 1 else f"empty trajectory.csv with status {summary.get('status')}"
    numbers = table[[c for c in table.columns if not c.endswith(".mode")]].to_numpy(dtype=float)
    status = summary.get("status")
    if not np.all(np.isfinite(numbers)):
        return f"non-finite values in trajectory.csv (status {status})"
    if code == 0 and status not in ("ok", "stopped"):
        return f"exit 0 with status {status!r}"
    t_end, t_last = summary["params"]["simulation"]["t_end"], float(table["t"].iloc[-1])
    stopped = status == "stopped" or "stopped" in str(summary.get("message", ""))
    if code == 0 and not stopped and abs(t_last - t_end) > 1e-9 * max(1.0, abs(t_end)):
        return f"status ok but the last sample is at t = {t_last:.9g}, not t_end = {t_end:.9g}"
    return ""


def warm_up(tmp: Path) -> None:
    """Run each example once, unbounded in wall time: the first compiled run compiles the
    engine (minutes after a source change), which is not a hang."""
    from nonsmooth_rod.cli import main

    for name, data in load_examples():
        path = tmp / f"warm-{name}.json"
        write_json(bounded(copy.deepcopy(data), ""), path)
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            main(["run", str(path), "--out", str(tmp / "warm"), "--no-plot", "--quiet"])


def battery(seed: int, count: int, subprocesses: int = 0, verbose: bool = False) -> dict:
    """Run `count` mutants in-process (and the first `subprocesses` of them again as real
    commands); returns counts and the failures."""
    results = {"mutants": count, "refused": 0, "ran": 0, "failures": [], "seconds": 0.0}
    with tempfile.TemporaryDirectory() as tmp:
        warm_up(Path(tmp))
        start = time.perf_counter()
        for k, (name, data, description) in enumerate(mutants(seed, count)):
            path, out_dir = Path(tmp) / f"{name}.json", Path(tmp) / f"out{k}"
            write_json(data, path)
            runs = [run_in_process] + ([run_subprocess] if k < subprocesses else [])
            for runner in runs:
                code, stderr, problem = runner(path, out_dir)
                try:
                    verdict = judge(code, stderr, problem, out_dir)
                except Exception as err:  # noqa: BLE001 - unreadable output is a finding too
                    verdict = f"output not readable: {type(err).__name__}: {str(err)[:200]}"
                if verdict:
                    results["failures"].append(f"{name}: {description}: {verdict}")
                elif runner is run_in_process:
                    results["refused" if code == 2 else "ran"] += 1
            if verbose and verdict:
                print(f"FAIL {name}: {description}: {verdict}", flush=True)
    results["seconds"] = time.perf_counter() - start
    return results


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the test suite's battery: 200 mutants, 3 subprocesses")
    parser.add_argument("--mutants", type=int, default=3000)
    parser.add_argument("--subprocesses", type=int, default=40)
    parser.add_argument("--seed", type=int, default=29)
    args = parser.parse_args(argv)
    count, subprocesses = (200, 3) if args.quick else (args.mutants, args.subprocesses)
    results = battery(args.seed, count, subprocesses, verbose=True)
    print(f"{results['mutants']} mutants in {results['seconds']:.1f} s: {results['refused']} refused cleanly, "
          f"{results['ran']} plausible runs, {len(results['failures'])} failures")
    return 1 if results["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
