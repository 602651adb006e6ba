"""The fuzzing battery of issue 29 in the suite: seeded mutants of the ten example scenes through
`nonsmooth-rod run` (in-process, a few as real commands), each a clean refusal (exit 2, one line)
or a plausible run (finite, ok or a failure said in one line, ending at t_end) — never a
traceback, a hang or a wrong ok. The larger battery: python benchmarks/fuzz_inputs.py."""
from __future__ import annotations

from pathlib import Path
from scripts import load_script


BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "fuzz_inputs.py"


def _bench():
    return load_script(BENCH)


def test_mutants_of_the_examples_are_refused_cleanly_or_run_plausibly():
    results = _bench().battery(seed=29, count=200, subprocesses=3)
    assert not results["failures"], "\n".join(results["failures"])  # overshooting t_end included
    assert results["refused"] > 50 and results["ran"] > 20  # the battery exercises both outcomes


def test_the_generator_is_seeded_and_bounded():
    bench = _bench()
    first, again = bench.mutants(5, 30), bench.mutants(5, 30)
    assert [d for _, _, d in first] == [d for _, _, d in again]
    for _, data, description in first:
        sim = data.get("simulation")
        if isinstance(sim, dict) and "t_end" not in description and isinstance(sim.get("t_end"), float):
            assert sim["t_end"] <= bench.T_END_CAP
