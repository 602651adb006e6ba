"""benchmarks/bench_startup.py --quick runs (timings are not asserted), and a Moreau–Jean run of
a scene leaves the heavy imports alone (issue 16)."""
import os
import subprocess
import sys
from pathlib import Path
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def test_bench_startup_quick_runs(capsys):
    module = load_script(ROOT / "benchmarks" / "bench_startup.py")
    assert module.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert [line.split()[1] for line in out.splitlines() if line.startswith("import ")] == list(module.ENTRY_POINTS)
    cold = [line for line in out.splitlines() if line.startswith("first run, empty cache:")]
    assert len(cold) == 1 and ("interpreted" in cold[0] or "compiled" in cold[0])
    ratios = [float(line.split()[-1]) for line in out.splitlines() if line.startswith("rod h=")]
    assert len(ratios) == 2 and all(r >= 1.0 for r in ratios)  # the whole call contains the integrator


def test_moreau_jean_run_of_a_scene_does_not_import_scipy_integrate():
    code = ("import sys, nonsmooth_rod as nr\n"
            "from nonsmooth_rod import toys\n"
            "toy = toys.BlockOnIncline(); q0, v0 = toy.initial_state()\n"
            "run = nr.simulate(toy.scene(), q0, v0, 0.01, method='moreau-jean', h=1e-3)\n"
            "assert run.status == 'ok', run.message\n"
            "print(sorted(m for m in ('scipy.integrate', 'matplotlib', 'rich') if m in sys.modules))\n")
    # interpreted: the imports are the same, and the subprocess does not compile the engine
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NONSMOOTH_ROD_NO_JIT="1")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[-2] == "[]"


def test_every_benchmark_ends_with_its_main_guard():
    """A definition after `if __name__ == "__main__":` exists when the module is imported (the
    tests) but not when it runs as a script: bench_startup.py once failed that way."""
    import ast

    for path in sorted((ROOT / "benchmarks").glob("*.py")):
        body = ast.parse(path.read_text()).body
        guards = [i for i, node in enumerate(body) if isinstance(node, ast.If) and "__main__" in ast.unparse(node.test)]
        assert not guards or guards[-1] == len(body) - 1, f"{path.name}: statements after the main guard"
