"""Figures: each one is read back and its plotted data compared with the simulation's arrays."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from PIL import Image

from nonsmooth_rod.rod.figures import (
    cases_figure,
    hypotheses_figure,
    impact_detail_figure,
    rolling_series,
)
from nonsmooth_rod.rod.problem import RodProblem
from nonsmooth_rod.rod.plotting import (
    DATA_GID,
    MARKER_GID,
    PANEL_SERIES,
    ROLLING_GID,
    RunData,
    axis,
    drawn_series,
    frame_indices,
    frames_figure,
    panel_figure,
    plot_run,
    rod_outline,
    write_gif,
)
from nonsmooth_rod.rod.hypotheses import rolling_hypothesis, sliding_hypothesis
from nonsmooth_rod.rod.simulation import simulate
from nonsmooth_rod.validation import InputError

BLUE, RED = to_rgba("tab:blue"), to_rgba("tab:red")


@pytest.fixture(scope="module")
def case2():
    """The paper's case 2: rolling until T/N reaches +μs at t_r1 ≈ 0.1041 s, then sliding."""
    return simulate(RodProblem.paper(2))


@pytest.fixture(scope="module")
def case2_mj():
    return simulate(RodProblem.paper(2), "moreau-jean", h=1e-3)


def test_panel_draws_the_runs_own_arrays(case2, case2_mj):
    data, mj = RunData.from_run(case2), RunData.from_run(case2_mj)
    fig = panel_figure(data, mj)
    for key, _ in PANEL_SERIES:
        ax = axis(fig, key)
        t, y = drawn_series(ax, DATA_GID)
        np.testing.assert_array_equal(t, case2.table["t"])
        np.testing.assert_array_equal(y, data.series(key))
        tm, ym = drawn_series(ax, MARKER_GID)
        np.testing.assert_array_equal(tm, case2_mj.table["t"])
        np.testing.assert_array_equal(ym, mj.series(key))
    # (a): T/N of the rolling hypothesis, and the ±μs levels.
    ax = axis(fig, "rolling_T_over_N")
    (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == ROLLING_GID]
    np.testing.assert_array_equal(line.get_xdata(), case2.rolling.t)
    np.testing.assert_array_equal(line.get_ydata(), case2.rolling.T_over_N)
    levels = sorted(ln.get_ydata()[0] for ln in ax.get_lines() if ln.get_gid() != ROLLING_GID
                    and np.ptp(ln.get_ydata()) == 0)
    assert levels == pytest.approx([-0.28, 0.28])
    # (b): the characteristic times as text: t_r1 = 0.10410 s, max T/N = 0.2900.
    text = axis(fig, "info").texts[0].get_text()
    assert f"{case2.rolling.t_r1:.5f}" in text and "0.10410" in text
    assert "max T/N = 0.2900" in text


def test_panel_colours_rolling_blue_and_sliding_red(case2):
    fig = panel_figure(RunData.from_run(case2))
    pieces = [ln for ln in axis(fig, "theta").get_lines() if ln.get_gid() == DATA_GID]
    # stick, slip−, slip+: three pieces, blue then red, switching at the phase boundaries.
    assert [to_rgba(ln.get_color()) for ln in pieces] == [BLUE, RED, RED]
    assert pieces[0].get_xdata()[-1] == pytest.approx(case2.phases[0].t_end, abs=1e-12)
    assert pieces[1].get_xdata()[0] == pytest.approx(case2.phases[0].t_end, abs=1e-12)
    assert case2.phases[0].t_end == pytest.approx(case2.rolling.t_r1, abs=1e-6)
    # The actual T/N equals T/N(0) = 0.2628 while rolling and −μd·sgn(v_C) = ±0.2 while sliding.
    t, ratio = drawn_series(axis(fig, "T_over_N"))
    assert ratio[0] == pytest.approx(case2.rolling.T_over_N_initial, rel=1e-6)
    sliding = (t > case2.phases[1].t_start + 1e-6) & (t < case2.phases[1].t_end - 1e-6)
    np.testing.assert_allclose(ratio[sliding], 0.20, rtol=1e-9)


def test_panel_png_and_svg_files(case2, tmp_path):
    written = plot_run(case2, tmp_path / "panel.png", formats=("png", "svg"), dpi=60)
    assert [p.name for p in written] == ["panel.png", "panel.svg"]
    with Image.open(tmp_path / "panel.png") as im:
        assert im.format == "PNG"
        assert im.size == (1200, 456)  # 20 × 7.6 in at 60 dpi
        pixels = np.asarray(im.convert("RGB"), dtype=int)
    # Both regime colours really are on the image (not a blank canvas).
    for colour in (BLUE, RED):
        rgb = np.array([round(255 * c) for c in colour[:3]])
        assert np.sum(np.all(np.abs(pixels - rgb) < 40, axis=-1)) > 200
    assert (tmp_path / "panel.png").stat().st_size > 20_000
    root = ET.parse(tmp_path / "panel.svg").getroot()
    assert root.tag.endswith("svg")


def test_frames_draw_the_rod_at_the_tables_poses(case2):
    data = RunData.from_run(case2)
    fig = frames_figure(data, n_frames=6)
    idx = frame_indices(case2.table["t"], 6)
    assert idx[0] == 0 and idx[-1] == len(case2.table["t"]) - 1
    for k, i in enumerate(idx):
        ax = axis(fig, f"frame{k}")
        (rod,) = [ln for ln in ax.get_lines() if ln.get_gid() == "rod"]
        pose = rod_outline(data.problem, case2.table["x_O"][i], case2.table["theta"][i])
        ends = np.array([pose["A"], pose["B"]])
        np.testing.assert_allclose(rod.get_xydata(), ends, rtol=0, atol=500 * np.finfo(float).eps * np.max(np.abs(ends)))
        (dot,) = [ln for ln in ax.get_lines() if ln.get_gid() == "contact"]
        assert to_rgba(dot.get_color()) == (BLUE if case2.table["mode"][i] == "stick" else RED)
    # The last frame is the impact: the axis is horizontal, ball B's centre at ball A's height.
    pose = rod_outline(data.problem, case2.table["x_O"][idx[-1]], case2.table["theta"][idx[-1]])
    assert pose["B"][1] == pytest.approx(data.problem.ball_radius, abs=1e-9)
    with pytest.raises(InputError):
        frames_figure(data, n_frames=1)


def test_gif_has_the_requested_frames(case2, tmp_path):
    path = write_gif(RunData.from_run(case2), tmp_path / "rod.gif", n_frames=5, dpi=40)
    with Image.open(path) as im:
        assert im.format == "GIF"
        assert im.n_frames == 5


def test_cases_overlay_draws_each_cases_run():
    runs = [RunData.from_run(simulate(RodProblem.paper(c))) for c in (1, 2, 3)]
    fig = cases_figure(runs)
    for key in ("theta", "theta_dot", "x_O", "x_O_dot"):
        ax = axis(fig, key)
        for k, run in enumerate(runs):
            (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == f"case{k}"]
            np.testing.assert_array_equal(line.get_xdata(), run.table["t"])
            np.testing.assert_array_equal(line.get_ydata(), run.table[key])
    # The paper's reading of Fig. 20: small friction moves ball A left first, larger friction
    # moves it right throughout (case 3) — here x_O of case 1 reaches −6.6 cm.
    assert runs[0].table["x_O"].min() < -0.06
    assert runs[2].table["x_O"].min() > -1e-9


def test_hypotheses_figure_draws_both_hypotheses():
    p = RodProblem.paper(None, mu_s=0.257, mu_d=0.257)
    fig = hypotheses_figure(0.257)
    roll = rolling_series(p, rolling_hypothesis(p))
    sh = sliding_hypothesis(p)
    for key in ("theta", "x_O", "theta_dot", "x_O_dot", "theta_ddot", "x_O_ddot"):
        ax = axis(fig, key)
        (lr,) = [ln for ln in ax.get_lines() if ln.get_gid() == "rolling"]
        (ls,) = [ln for ln in ax.get_lines() if ln.get_gid() == "sliding"]
        np.testing.assert_array_equal(lr.get_ydata(), roll[key])
        np.testing.assert_array_equal(ls.get_ydata(), getattr(sh, key))
    # Rolling: x_O = −r(θ − θ0); at the horizontal x_O = r θ0 = 0.02 · π/3.
    assert roll["x_O"][-1] == pytest.approx(0.02 * math.pi / 3, rel=1e-9)


def test_impact_detail_window_holds_the_last_switch():
    fig = impact_detail_figure((0.25, 0.30))
    for mu in (0.25, 0.30):
        sh = sliding_hypothesis(RodProblem.paper(None, mu_s=mu, mu_d=mu))
        last = max(list(sh.reversals) + [b for _, b in sh.filippov])
        lo, hi = axis(fig, f"mu{mu:g}:detail").get_xlim()
        assert lo < last < hi and hi - lo == pytest.approx(0.04)
        (line,) = [ln for ln in axis(fig, f"mu{mu:g}:full").get_lines() if ln.get_gid() == "sliding"]
        np.testing.assert_array_equal(line.get_ydata(), sh.theta_dot)
    # μ = 0.30 exceeds T/N(0) = 0.263: the sliding solution is held at v_C = 0 from the start.
    assert sliding_hypothesis(RodProblem.paper(None, mu_s=0.3, mu_d=0.3)).filippov[0][0] == 0.0
