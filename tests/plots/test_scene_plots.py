"""Figures and animations of any scene: what is drawn where (shapes, lines, force arrows, ±μs bands)."""
import math
from pathlib import Path

import numpy as np
import pytest

from nonsmooth_rod.cli import main
from nonsmooth_rod.plots.animation import (
    animate,
    body_outline,
    body_size,
    build_animation,
    contact_frames,
    write_animation,
)
from nonsmooth_rod.plots.scene_figure import plot_result, result_figure
from nonsmooth_rod.scenefile import load_scene, simulate_scene

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
ROUNDOFF = 500 * np.finfo(float).eps  # a few hundred ulps, relative to the quantity's scale


@pytest.fixture(scope="module")
def ladder_run():
    sf = load_scene(SCENES / "ladder.toml", ["simulation.t_end=0.05"])
    return simulate_scene(sf)


def test_outlines_follow_the_declared_shapes():
    sf = load_scene(SCENES / "paper_rod.toml")
    prims = body_outline(sf, 0)
    assert [p[0] for p in prims] == ["segment", "circle", "circle"]
    assert prims[1] == ("circle", (-0.205, 0.0), 0.02) and prims[2] == ("circle", (0.205, 0.0), 0.02)
    # the drawn balls sit exactly on the contacts' disks
    assert [(p[1], p[2]) for p in prims[1:]] == [(c.offset, c.radius) for c in sf.scene.contacts]
    block = load_scene(SCENES / "rocking_block.toml")
    (kind, _), = body_outline(block, 0)
    assert kind == "polygon" and body_size(block, 0) == pytest.approx(math.hypot(0.1, 0.3), rel=1e-13)


def test_a_body_without_shape_is_drawn_from_its_contacts():
    sf = load_scene(SCENES / "rocking_block.toml")
    sf.shapes["block"] = {}
    prims = body_outline(sf, 0)
    kinds = [p[0] for p in prims]
    assert kinds == ["polygon", "dot", "dot", "cross"]
    hull = np.array(prims[0][1])
    # the hull of the two corners and the centre of mass
    assert sorted(map(tuple, np.round(hull, 12))) == [(-0.1, -0.3), (0.0, 0.0), (0.1, -0.3)]


def test_contact_frames_are_the_touching_points(ladder_run):
    sf = ladder_run.scene_file
    (foot, _, _), (top, n_top, _) = contact_frames(sf.scene, sf.q0)
    length = 2.0  # the ladder's; positions are computed through its angle
    np.testing.assert_allclose(foot, [1.0, 0.0], rtol=0, atol=ROUNDOFF * length)
    np.testing.assert_allclose(top, [0.0, 2 * math.sin(math.radians(60))], rtol=0, atol=ROUNDOFF * length)
    np.testing.assert_allclose(n_top, [1.0, 0.0], rtol=0, atol=ROUNDOFF)  # the wall pushes along +x


def test_figure_has_every_panel_and_the_friction_bands(ladder_run, tmp_path):
    fig = result_figure(ladder_run)
    labels = {ax.get_label() for ax in fig.axes}
    assert {"paths", "coordinates", "forces", "ratios", "phases"} <= labels
    ratios = next(ax for ax in fig.axes if ax.get_label() == "ratios")
    levels = sorted({round(float(line.get_ydata()[0]), 12) for line in ratios.lines if line.get_linestyle() == ":"})
    assert levels == [-0.5, 0.0, 0.5]  # ±μs of the foot, 0 of the frictionless top
    path = plot_result(ladder_run, tmp_path / "figure.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_animation_frames_move_the_bodies(ladder_run):
    anim = build_animation(ladder_run, frames=4, dpi=40)
    fig = anim._fig
    ax = fig.axes[0]
    anim._func(3)
    patch = ax.patches[0] if ax.patches else None
    line = next(ln for ln in ax.lines if ln.get_transform() is not ax.transData)
    q = ladder_run.trajectory.q[-1]
    # the rod's end (1, 0) in its frame lands on the top of the ladder in the world
    world = line.get_transform().transform([1.0, 0.0])
    assert np.allclose(ax.transData.inverted().transform(world), [q[0] + math.cos(q[2]), q[1] + math.sin(q[2])])
    assert patch is None  # a rod is a segment, nothing filled
    anim._draw_was_started = True  # drawn by hand: no "deleted without rendering" warning


def test_write_animation_gif_and_mp4_note(ladder_run, tmp_path):
    notes = write_animation(ladder_run, tmp_path, frames=3, fps=10)
    from PIL import Image

    with Image.open(tmp_path / "animation.gif") as im:
        assert im.n_frames == 3
    from nonsmooth_rod.plots.animation import ffmpeg_available

    assert (tmp_path / "animation.mp4").exists() == ffmpeg_available()
    assert any("ffmpeg" in n for n in notes) != ffmpeg_available()


def test_animate_command_and_inline_html(tmp_path, ladder_run, capsys):
    out = tmp_path / "run"
    assert main(["run", str(SCENES / "ball_collisions.toml"), "--out", str(out), "--quiet", "--no-plot"]) == 0
    assert main(["animate", str(out), "--frames", "3", "--quiet"]) == 0
    assert (out / "animation.gif").exists()
    assert main(["animate", str(out), "--frames", "1"]) == 2
    html = animate(ladder_run, frames=2)
    text = html if isinstance(html, str) else html.data
    assert "<script" in text and "animation" in text.lower()
