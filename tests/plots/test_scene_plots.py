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
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left
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


def _ball_row(n: int, name_length: int = 12):
    """n balls rolling on a floor, one contact each, with long contact names: a wide, flat scene."""
    from nonsmooth_rod.scenefile import parse_scene

    names = [f"ball{i}" for i in range(n)]
    data = {"schema": "nonsmooth-rod/scene/1",
            "bodies": [{"name": b, "shape": "disk", "radius": 0.05, "mass": 1.0, "collide": False}  # only the
                       for b in names],  # declared contacts: one each
            "lines": [{"name": "floor"}],
            "contacts": [{"kind": "disk-on-line", "name": f"{b}-on-floor".ljust(name_length, "x"), "body": b,
                          "line": "floor", "radius": 0.05, "law": {"mu_s": 0.3, "mu_d": 0.2}} for b in names],
            "initial": {b: {"q": [0.3 * i, 0.05, 0.0], "v": [1.0 - 0.5 * (i % 3), 0.0, 0.0]}
                        for i, b in enumerate(names)},
            "simulation": {"t_end": 0.02, "h": 1e-3}}
    return simulate_scene(parse_scene(data))


@pytest.mark.parametrize("n_contacts", [1, 3, 7])
def test_a_frame_shows_its_labels_and_status_whole(n_contacts, tmp_path):
    """A flat scene made 480×192 frames that cut the x label off, and the status of three or more
    contacts ran off the frame: every label and the whole status text now lie inside the frame."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    result = _ball_row(n_contacts)
    anim = build_animation(result, frames=3)
    fig = anim._fig
    anim._func(2)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    ax = fig.axes[0]
    frame = fig.bbox
    status = fig.texts[0]
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    ticks = [t for t in ax.get_xticklabels() if x0 <= t.get_position()[0] <= x1] + \
        [t for t in ax.get_yticklabels() if y0 <= t.get_position()[1] <= y1]  # the ones drawn
    parts = [ax.xaxis.label, ax.yaxis.label, status, *ticks]
    for artist in parts:
        box = artist.get_window_extent(renderer)
        assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1, artist
    assert not status.get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))
    assert all(name in status.get_text() for name in result.contact_names)
    width, height = (int(round(x)) for x in fig.get_size_inches() * fig.dpi)
    assert width % 2 == 0 and height % 2 == 0  # video encoders want even sizes
    canvas.print_png(tmp_path / "frame.png")
    with Image.open(tmp_path / "frame.png") as im:
        assert im.size == (width, height)
    anim._draw_was_started = True


def test_the_phase_bar_shares_no_colour_with_the_line_plots():
    """Bodies and contacts are C0, C1, ... in the line plots; the phase bar's states are greys
    and hatches (its own legend), so 'stick' cannot be read as 'the first body'."""
    from matplotlib.colors import to_rgb

    from nonsmooth_rod.plots.scene_figure import MODE_STYLES

    result = _ball_row(3)
    fig = result_figure(result)
    phases = next(ax for ax in fig.axes if ax.get_label() == "phases")
    line_colours = {to_rgb(line.get_color()) for ax in fig.axes for line in ax.lines
                    if ax is not phases and line.get_linestyle() != "None"}
    assert len(line_colours) >= 3
    bars = [c for c in phases.collections if (c.get_gid() or "").startswith("phase:")]
    assert {c.get_gid().rsplit(":", 1)[1] for c in bars} <= set(MODE_STYLES)
    for bar in bars:
        r, g, b = bar.get_facecolor()[0][:3]
        assert r == g == b and (r, g, b) not in line_colours  # a grey, never a series' hue
    looks = {(to_rgb(s["facecolor"]), s["hatch"]) for s in MODE_STYLES.values()}
    assert len(looks) == len(MODE_STYLES)  # each state its own look
    legend = [t.get_text() for t in phases.get_legend().get_texts()]
    assert legend == ["open", "stick", "slip+", "slip−", "impact"]


def test_segments_are_drawn_end_to_end_and_their_contact_frames_follow_the_feature(tmp_path):
    sf = load_scene(SCENES / "ball_off_table.toml", ["simulation.t_end=0.2"])
    run = simulate_scene(sf)
    fig = result_figure(run)
    paths = next(ax for ax in fig.axes if ax.get_label() == "paths")
    drawn = [np.column_stack([line.get_xdata(), line.get_ydata()]) for line in paths.lines]
    assert any(d.shape == (2, 2) and np.array_equal(d, [[-1.0, 0.0], [0.0, 0.0]]) for d in drawn)
    # on the table's top: the point below the centre; past its end: the end point, normal to the centre
    (point, normal, tangent), = contact_frames(sf.scene, np.array([-0.5, 0.1, 0.0]))
    np.testing.assert_allclose([point, normal, tangent], [[-0.5, 0.0], [0.0, 1.0], [1.0, 0.0]], atol=ROUNDOFF)
    (point, normal, _), = contact_frames(sf.scene, np.array([0.06, 0.08, 0.0]))
    np.testing.assert_allclose([point, normal], [[0.0, 0.0], [0.6, 0.8]], atol=ROUNDOFF)
    anim = build_animation(run, frames=3, dpi=40)
    anim._func(2)
    ax = anim._fig.axes[0]
    assert ax.get_xlim()[0] < -1.0 and ax.get_xlim()[1] > 0.0  # the view holds the whole table
    assert any(np.array_equal(np.column_stack([ln.get_xdata(), ln.get_ydata()]), [[-1.0, 0.0], [0.0, 0.0]])
               for ln in ax.lines)
    anim._draw_was_started = True  # drawn by hand: no "deleted without rendering" warning


def test_a_pin_is_drawn_as_a_ring_at_its_point_moving_with_its_body():
    sf = load_scene(SCENES / "pendulum_wall.toml", ["simulation.t_end=0.3", "simulation.h=1e-3"])
    run = simulate_scene(sf)
    anim = build_animation(run, frames=3, dpi=40)
    ax = anim._fig.axes[0]
    anim._func(2)
    ring = next(ln for ln in ax.lines if ln.get_marker() == "o" and ln.get_markerfacecolor() == "white")
    world = ax.transData.inverted().transform(ring.get_transform().transform(np.column_stack(ring.get_data())))
    np.testing.assert_allclose(world[0], [0.0, 0.0], atol=1e-12)  # the pivot stays at the world origin
    anim._draw_was_started = True
