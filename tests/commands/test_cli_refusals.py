"""A hostile user's inputs to the CLI: each refused with one line naming the option, exit 2,
never a traceback, never a run on garbage (issue 17's battery, simulate and plot)."""
import pytest

from nonsmooth_rod.cli import main

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

SIMULATE = [
    (["--length", "1e308"], "--length"),
    (["--mass", "1e308", "--xi", "0.2", "--inertia", "0.02"], "--mass"),
    (["--g", "1e308"], "--g"),
    (["--mass", "0.6", "--xi", "0.2", "--inertia", "1e308"], "--inertia"),
    (["--method", "regularized", "--stiffness", "1e308"], "--stiffness"),
    (["--method", "regularized", "--damping", "1e308"], "--damping"),
    (["--t-end", "1e308"], "--t-end"),
    (["--min-phase", "nan"], "--min-phase"),
    (["--min-phase", "inf"], "--min-phase"),
    (["--min-phase", "1e308"], "--min-phase"),
    (["--method", "regularized", "--ode-method", ""], "--ode-method"),
    (["--rtol", "1e308"], "--rtol"),
    (["--rtol", "0"], "--rtol must be positive"),
    (["--max-step", "-1"], "--max-step must be positive"),
    (["--density", "1e308"], "--density"),
    (["--ball-radius", "-0.02"], "--ball-radius must be positive"),
    (["--theta0-deg", "inf"], "--theta0-deg"),
    (["--restitution", "2"], "--restitution"),
    (["--h", "1e-300", "--method", "moreau-jean"], "--h"),
]


@pytest.mark.parametrize("args, fragment", SIMULATE)
def test_simulate_refuses_with_one_line(tmp_path, capsys, args, fragment):
    code = main(["simulate", "--no-plot", "--quiet", "--out", str(tmp_path / "out"), *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("nonsmooth-rod: error:") and fragment in err
    assert not (tmp_path / "out").exists()  # nothing ran, nothing written


@pytest.mark.parametrize("formats", ["png,svg,png", "png,,png", "svg,jpg"])
def test_plot_refuses_duplicate_or_unknown_formats(tmp_path, capsys, formats):
    assert main(["plot", str(tmp_path), "--format", formats]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--format" in err
