"""benchmarks/bench_scenes.py --quick runs and prints its table (timings are not asserted).

Run in this process, not a subprocess: it shares the kernels this test process has compiled (or
loaded from the cache) instead of compiling the engine again, and measures neither the cold
compile (--no-compile-time) nor MuJoCo (the ladder is not a ball row).
"""
from pathlib import Path
from scripts import load_script

ROOT = Path(__file__).resolve().parents[2]


def _benchmark(name):
    return load_script(ROOT / "benchmarks" / f"{name}.py")


def _bench_scenes():
    return _benchmark("bench_scenes")


def test_bench_scenes_quick_runs(capsys):
    assert _bench_scenes().main(["--quick", "--only", "ladder", "--no-compile-time"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("ladder")]
    assert [line.split()[2] for line in lines] == ["lemke", "pgs"]
    assert all(line.split()[-1] == "True" for line in lines)  # compiled


def test_bench_moreau_jean_quick_labels_compiled_and_interpreted_rows(capsys):
    assert _benchmark("bench_moreau_jean").main(["--quick"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if "(compiled)" in line
            or "(interpreted)" in line]
    labels = [" ".join(row[:2]) for row in rows]
    assert labels == [f"{s} (compiled)" for s in ("lemke", "pgs", "enum")] + \
        [f"{s} (interpreted)" for s in ("lemke", "pgs", "enum")]
    assert all("FAILED" not in " ".join(row) and int(row[-1]) > 0 for row in rows)  # every run reached B's impact


def test_bench_scenes_targets_quick_print_every_case(capsys):
    module = _bench_scenes()
    module.targets(1, quick=True)
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:]]
    assert len(rows) == 2 * (1 + len(module.ONE_CONTACT) + len(module.TWO_CONTACTS))
    for row in rows:
        whole, target, whole_over_loop = float(row[-3]), float(row[-2]), float(row[-1])
        assert whole > 0 and target in (0.2, 0.3, 0.4) and whole_over_loop >= 1.0  # the call contains its loop


def test_bench_scenes_fixed_cost_prints_every_one_body_scene(capsys):
    module = _bench_scenes()
    assert module.main(["--fixed-cost"]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:]]
    assert [row[1] for row in rows] == list(module.ONE_CONTACT) + ["BlockOnIncline"]
    for row in rows:
        whole, loop, outside, ratio, one_step = map(float, row[-5:])
        assert whole >= loop > 0 and ratio >= 1.0  # the call contains its loop
        assert abs(whole - loop - outside) <= 0.15  # the columns' rounding
        assert 0 < one_step
