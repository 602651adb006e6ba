"""Animations of any scene: bodies (disks, balls, rectangles, polygons, rods), lines, segments and contact forces.

How a body is drawn: from its `shape` in the scene file (disk/ball: a circle with a spoke to show
the turn; rectangle; rod: a segment; rod-with-balls: a segment with a ball at each end, the centre
of mass in the middle). A body without a shape is drawn from its contacts: a circle for each disk
contact (offset, radius), a dot for each point contact, joined by their convex hull (or a segment),
and the centre of mass as a cross. Contact forces are arrows N n + T t at the contact point. Joints:
a ring at each pin's points, a square at each slider's, on the bodies they join.

    write_animation(result, "out/")          -> animation.gif (+ animation.mp4 if ffmpeg exists)
    animate(result)                          -> inline HTML animation for notebooks
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..io import atomic_path
from ..model.contacts import DiskOnDisk, DiskOnLine, DiskOnSegment, LinearRelation, SegmentEndOnEdge, VertexOnEdge
from ..model.joints import Pin
from ..validation import InputError


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points (monotone chain), counter-clockwise."""
    pts = sorted(set(map(tuple, np.round(points, 12))))
    if len(pts) < 3:
        return np.array(pts)

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    return np.array(half(pts)[:-1] + half(pts[::-1])[:-1])


def _contact_parts(scene, body: int) -> list:
    """(offset, radius) of every disk or point of `body` that touches something."""
    parts = []
    for c in scene.contacts:
        if isinstance(c, (DiskOnLine, DiskOnSegment)) and c.body == body:
            parts.append((tuple(c.offset), c.radius))
        elif isinstance(c, SegmentEndOnEdge) and c.body == body:
            parts += [(tuple(c.edge_start), 0.0), (tuple(c.edge_end), 0.0)]
        elif isinstance(c, VertexOnEdge):
            if c.vertex_body == body:
                parts.append((tuple(c.vertex), c.radius))
            if c.edge_body == body:
                parts += [(tuple(c.edge_start), 0.0), (tuple(c.edge_end), 0.0)]
        elif isinstance(c, DiskOnDisk):
            if c.body_a == body:
                parts.append((tuple(c.offset_a), c.radius_a))
            if c.body_b == body:
                parts.append((tuple(c.offset_b), c.radius_b))
    return parts


def body_outline(sf, body: int) -> list:
    """Primitives in the body frame: ("circle", (x, y), r), ("polygon", points), ("segment", p0, p1)."""
    shape = sf.shapes.get(sf.body_names[body]) or {}
    kind = shape.get("shape")
    if kind in ("disk", "ball"):
        r = shape["radius"]
        return [("circle", (0.0, 0.0), r), ("segment", (0.0, 0.0), (r, 0.0))]
    if kind == "rectangle":
        a, b = shape["width"] / 2, shape["height"] / 2
        return [("polygon", [(-a, -b), (a, -b), (a, b), (-a, b)])]
    if kind == "polygon":
        return [("polygon", [tuple(p) for p in shape["vertices"]])]
    if kind == "rod":
        return [("segment", (-shape["length"] / 2, 0.0), (shape["length"] / 2, 0.0))]
    if kind == "rod-with-balls":
        half, r = shape["length"] / 2, shape["ball_radius"]
        return [("segment", (-half, 0.0), (half, 0.0)), ("circle", (-half, 0.0), r), ("circle", (half, 0.0), r)]
    return _outline_from_contacts(sf, body)


def joint_points(scene, body: int) -> list:
    """(kind, point) in `body`'s frame of every joint it takes part in: ("pin" | "slider", (x, y))."""
    points = []
    for joint in getattr(scene, "joints", ()):
        if not hasattr(joint, "point_a"):  # a LinearJoint: no point to draw
            continue
        kind = "pin" if isinstance(joint, Pin) else "slider"
        if joint.body_a == body:
            points.append((kind, tuple(joint.point_a)))
        if joint.body_b == body:
            points.append((kind, tuple(joint.point_b)))
    return points


def _outline_from_contacts(sf, body: int) -> list:
    parts = _contact_parts(sf.scene, body) + [(point, 0.0) for _, point in joint_points(sf.scene, body)]
    prims = [("circle", off, r) if r > 0 else ("dot", off) for off, r in parts]
    points = np.array([off for off, _ in parts] + [(0.0, 0.0)])
    hull = _hull(points)
    if len(hull) >= 3:
        prims.insert(0, ("polygon", [tuple(p) for p in hull]))
    elif len(hull) == 2:
        prims.insert(0, ("segment", tuple(hull[0]), tuple(hull[1])))
    prims.append(("cross", (0.0, 0.0)))
    return prims


def body_size(sf, body: int) -> float:
    """Largest distance of the drawing from the centre of mass."""
    size = 0.0
    for prim in body_outline(sf, body):
        if prim[0] == "circle":
            size = max(size, math.hypot(*prim[1]) + prim[2])
        else:
            pts = prim[1] if prim[0] == "polygon" else prim[1:]
            size = max([size] + [math.hypot(*p) for p in pts])
    return size


def scene_extent(result, sf) -> tuple[float, float, float, float]:
    """(xmin, xmax, ymin, ymax) covering every body at every sample, with a margin."""
    q = result.trajectory.q
    xs, ys = [], []
    for i in range(len(sf.body_names)):
        s = body_size(sf, i)
        xs += [np.min(q[:, 3 * i]) - s, np.max(q[:, 3 * i]) + s]
        ys += [np.min(q[:, 3 * i + 1]) - s, np.max(q[:, 3 * i + 1]) + s]
    for line in sf.lines.values():
        xs.append(line.point[0])
        ys.append(line.point[1])
    for segment in getattr(sf, "segments", {}).values():
        xs += [segment.a[0], segment.b[0]]
        ys += [segment.a[1], segment.b[1]]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    pad = 0.1 * max(x1 - x0, y1 - y0, 1e-3)
    x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
    widen = max(0.0, 0.6 * (y1 - y0) - (x1 - x0)) / 2  # keep the view from being a thin strip
    lift = max(0.0, 0.3 * (x1 - x0) - (y1 - y0)) / 2
    return x0 - widen, x1 + widen, y0 - lift, y1 + lift


def draw_lines(ax, sf, extent=None) -> list:
    """Each line of the scene: its own `length` if the file gives one, else across the extent.
    Returns (artist, motion) of the driven lines and segments (drawn at rest: moved per frame)."""
    if extent is not None and not isinstance(extent, tuple):  # a matplotlib Bbox
        extent = (extent.x0, extent.x1, extent.y0, extent.y1)
    tables = {t.get("name"): t for t in sf.data.get("lines", []) if isinstance(t, dict)}
    driven = []
    for name, line in sf.lines.items():
        length = tables.get(name, {}).get("length")
        if length is None:
            x0, x1, y0, y1 = extent or (-1.0, 1.0, -1.0, 1.0)
            length = 2 * (math.hypot(x1 - x0, y1 - y0) + math.hypot(line.point[0] - (x0 + x1) / 2,
                                                                       line.point[1] - (y0 + y1) / 2))
        t, n = np.array(line.tangent), np.array(line.normal)
        p = np.array(line.point)
        ends = np.array([p - t * length / 2, p + t * length / 2])
        artists = ax.plot(ends[:, 0], ends[:, 1], color="0.3", lw=2, zorder=1)
        below = 0.008 * (max(extent[1] - extent[0], extent[3] - extent[2]) if extent else length)
        hatch = np.array([ends[0] - below * n, ends[1] - below * n])
        artists += ax.plot(hatch[:, 0], hatch[:, 1], color="0.7", lw=4, zorder=0)
        driven += [(art, line.motion) for art in artists if line.motion is not None]
    return driven + draw_segments(ax, sf)


def draw_segments(ax, sf) -> list:
    """Each segment of the scene from end to end, its ends marked (a segment has two sides);
    returns (artist, motion) of the driven ones."""
    driven = []
    for segment in getattr(sf, "segments", {}).values():
        ends = np.array([segment.a, segment.b])
        artists = ax.plot(ends[:, 0], ends[:, 1], color="0.3", lw=2.5, solid_capstyle="butt", zorder=1)
        artists += ax.plot(ends[:, 0], ends[:, 1], "o", color="0.3", ms=3, zorder=1)
        driven += [(art, segment.motion) for art in artists if segment.motion is not None]
    return driven


def move_driven(ax, driven, t: float) -> None:
    """The driven lines' and segments' artists at their place at time t."""
    from matplotlib.transforms import Affine2D

    for art, motion in driven:
        d = motion.at(t)[0]
        art.set_transform(Affine2D().translate(d[0], d[1]) + ax.transData)


def _make_artists(ax, sf) -> list:
    """For each body, its artists in its own frame (moved each frame by a transform)."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Polygon

    colours = [f"C{i % 10}" for i in range(len(sf.body_names))]
    bodies = []
    for i, colour in enumerate(colours):
        artists = []
        for prim in body_outline(sf, i):
            if prim[0] == "circle":
                art = Circle(prim[1], prim[2], fc=colour, ec="k", alpha=0.6)
            elif prim[0] == "polygon":
                art = Polygon(prim[1], closed=True, fc=colour, ec="k", alpha=0.5)
            elif prim[0] == "segment":
                art = Line2D(*zip(prim[1], prim[2]), color="k", lw=2)
            else:
                art = Line2D([prim[1][0]], [prim[1][1]], marker="x" if prim[0] == "cross" else "o", color="k", ms=5)
            (ax.add_patch if hasattr(art, "set_facecolor") else ax.add_line)(art)
            artists.append(art)
        for kind, point in joint_points(sf.scene, i):  # a pin: a ring; a slider: a square
            art = Line2D([point[0]], [point[1]], marker="o" if kind == "pin" else "s", mfc="white", mec="k", ms=6,
                         zorder=6)
            ax.add_line(art)
            artists.append(art)
        bodies.append(artists)
    return bodies


def contact_frames(scene, q: np.ndarray) -> list[tuple]:
    """(point, normal, tangent) of every contact at configuration q (the force on the first body)."""
    out = []
    for c in scene.contacts:
        if isinstance(c, DiskOnDisk):
            ia, ib = 3 * c.body_a, 3 * c.body_b
            ca = _world(q, ia, c.offset_a)
            cb = _world(q, ib, c.offset_b)
            d = ca - cb
            n = d / max(np.linalg.norm(d), 1e-300)
            out.append((ca - c.radius_a * n, n, np.array([n[1], -n[0]])))
        elif isinstance(c, VertexOnEdge):  # at the vertex (or the disk's touching point); force on its first body
            j = 3 * c.bodies[0]
            k = c.kinematics(q, np.zeros_like(q), q.size)
            n, t = k.H_N[j: j + 2], k.H_T[j: j + 2]
            point = _world(q, 3 * c.vertex_body, c.vertex) - c.radius * n if c.vertex_body >= 0 else np.array(c.vertex)
            out.append((point, n, t))
        elif isinstance(c, (DiskOnSegment, SegmentEndOnEdge)):  # the touched feature's normal: from the kinematics
            j = 3 * c.body
            k = c.kinematics(q, np.zeros_like(q), q.size)
            n, t = k.H_N[j : j + 2], k.H_T[j : j + 2]
            if isinstance(c, SegmentEndOnEdge):  # at the segment's end point
                out.append((np.array(c.segment.a if c.end == "a" else c.segment.b), n, t))
            else:
                out.append((_world(q, j, c.offset) - c.radius * n, n, t))
        elif isinstance(c, LinearRelation):  # no contact point: its first body's centre, its (x, y) rows
            j = c.bodies[0]
            rows = (c.normal.get(j, (0.0, 0.0, 0.0)), c.tangent.get(j, (0.0, 0.0, 0.0)))
            out.append((np.array(q[3 * j: 3 * j + 2], dtype=float), *(np.array(r[:2]) for r in rows)))
        else:
            centre = _world(q, 3 * c.body, c.offset)
            n, t = np.array(c.line.normal), np.array(c.line.tangent)
            out.append((centre - c.radius * n, n, t))
    return out


def _world(q, i, offset) -> np.ndarray:
    c, s = math.cos(q[i + 2]), math.sin(q[i + 2])
    return np.array([q[i] + c * offset[0] - s * offset[1], q[i + 1] + s * offset[0] + c * offset[1]])


def _force_scale(result, extent) -> float:
    """Metres of arrow per newton: a typical (95th percentile) resting force spans a fifth of the view."""
    tr = result.trajectory
    mags = np.hypot(tr.normal_force, tr.tangential_force).ravel()
    mags = mags[np.isfinite(mags) & (mags > 0)]
    size = max(extent[1] - extent[0], extent[3] - extent[2])
    return 0.2 * size / np.percentile(mags, 95) if mags.size else 0.0


# A frame: the scene's box, 5.1 in wide, with fixed margins (inches) for the tick labels and the
# axis labels, and a band above it for the status text. Nothing depends on the frame's content,
# so nothing moves or is cut off from one frame to the next, whatever the scene's proportions.
FRAME_WIDTH_IN = 6.0
MARGINS_IN = {"left": 0.75, "right": 0.15, "bottom": 0.55, "top": 0.12}
STATUS_FONT_PT = 8
_CHAR_WIDTH_EM = 0.602  # DejaVu Sans Mono, matplotlib's monospace


# A scene with more contacts than this (shapes' candidate contacts: a box pair lists 32) is
# drawn with only the contacts that ever touch: the others are open throughout.
ALL_CONTACTS_UP_TO = 12


def shown_contacts(result) -> list[tuple[int, str]]:
    """(column, name) of the contacts the figure draws."""
    names = list(result.contact_names)
    if len(names) <= ALL_CONTACTS_UP_TO:
        return list(enumerate(names))
    return [(k, name) for k, name in enumerate(names)
            if any(str(ph.mode) != "open" for ph in result.phases.get(name, []))
            or np.any(result.trajectory.normal_force[:, k] != 0.0)]


class StatusText:
    """The time and every contact's state, in a fixed number of lines that fit the frame's width:
    each entry padded to one width, so the text does not jump as states change."""

    def __init__(self, contact_names):
        self.names = list(contact_names)
        self.width = max((len(n) for n in self.names), default=0) + len(":slip+")
        chars = int((FRAME_WIDTH_IN - 0.2) * 72 / (_CHAR_WIDTH_EM * STATUS_FONT_PT))
        self.per_line = max(1, (chars + 2) // (self.width + 2))
        self.lines = 1 + math.ceil(len(self.names) / self.per_line)

    def text(self, t: float, modes) -> str:
        cells = [f"{n}:{m}".ljust(self.width) for n, m in zip(self.names, modes)]
        rows = ["  ".join(cells[k:k + self.per_line]).rstrip() for k in range(0, len(cells), self.per_line)]
        return "\n".join([f"t = {t:.4f} s", *rows])


def _frame_figure(extent, status_lines: int, dpi: int):
    """The Figure and the scene's axes, laid out in inches (see MARGINS_IN)."""
    from matplotlib.figure import Figure

    m = MARGINS_IN
    box_w = FRAME_WIDTH_IN - m["left"] - m["right"]
    box_h = box_w * min(max((extent[3] - extent[2]) / (extent[1] - extent[0]), 0.4), 1.6)
    top = m["top"] + status_lines * STATUS_FONT_PT * 1.25 / 72
    height = m["bottom"] + box_h + top
    # Even pixel sizes: video encoders (H.264 in yuv420p) refuse odd ones.
    width, height = (2 * math.ceil(x * dpi / 2) / dpi for x in (FRAME_WIDTH_IN, height))
    fig = Figure(figsize=(width, height), dpi=dpi)
    ax = fig.add_axes((m["left"] / width, m["bottom"] / height, box_w / width, box_h / height), label="scene")
    # Equal scales by widening the view to the box's proportions, not by shrinking the box: it
    # stays where the margins put it, filled.
    x0, x1, y0, y1 = extent
    grow_x = max(0.0, (y1 - y0) * box_w / box_h - (x1 - x0)) / 2
    grow_y = max(0.0, (x1 - x0) * box_h / box_w - (y1 - y0)) / 2
    ax.set(xlim=(x0 - grow_x, x1 + grow_x), ylim=(y0 - grow_y, y1 + grow_y), aspect="equal",
           xlabel="x [m]", ylabel="y [m]")
    return fig, ax


def build_animation(result, sf=None, frames: int = 120, fps: int = 25, dpi: int = 80):
    """A matplotlib FuncAnimation of the run (frames evenly spaced in time)."""
    from matplotlib import animation
    from matplotlib.transforms import Affine2D

    from .frames import frame_indices

    sf = sf or getattr(result, "scene_file", None)
    if sf is None:
        raise InputError("animating a run needs its scene file (result.scene_file) to know the bodies' shapes")
    tr = result.trajectory
    extent = scene_extent(result, sf)
    shown = shown_contacts(result)
    status = StatusText([name for _, name in shown])
    fig, ax = _frame_figure(extent, status.lines, dpi)
    driven = draw_lines(ax, sf, extent)
    bodies = _make_artists(ax, sf)
    scale = _force_scale(result, extent)
    arrows = ax.quiver(np.zeros(len(sf.scene.contacts)), np.zeros(len(sf.scene.contacts)),
                       np.zeros(len(sf.scene.contacts)), np.zeros(len(sf.scene.contacts)),
                       angles="xy", scale_units="xy", scale=1.0, color="crimson", width=0.006, zorder=5)
    label = fig.text(0.1 / fig.get_figwidth(), 1 - 0.06 / fig.get_figheight(), "", va="top",
                     family="monospace", fontsize=STATUS_FONT_PT)
    indices = frame_indices(tr.t, frames)

    def update(k):
        i = indices[k]
        q = tr.q[i]
        for b, artists in enumerate(bodies):
            move = Affine2D().rotate(q[3 * b + 2]).translate(q[3 * b], q[3 * b + 1]) + ax.transData
            for art in artists:
                art.set_transform(move)
        if len(sf.scene.contacts):
            geo = contact_frames(sf.scene, q)
            pts = np.array([g[0] for g in geo])
            vec = np.array([tr.normal_force[i, c] * g[1] + tr.tangential_force[i, c] * g[2]
                            for c, g in enumerate(geo)]) * scale
            arrows.set_offsets(pts)
            arrows.set_UVC(vec[:, 0], vec[:, 1])
        label.set_text(status.text(tr.t[i], [tr.modes[i, k] for k, _ in shown]))
        move_driven(ax, driven, float(tr.t[i]))
        return []

    return animation.FuncAnimation(fig, update, frames=len(indices), interval=1000 / fps, blit=False)


def ffmpeg_available() -> bool:
    from matplotlib import animation

    return animation.writers.is_available("ffmpeg")


def write_animation(result, out_dir, frames: int = 120, fps: int = 25) -> list[str]:
    """animation.gif (and animation.mp4 where ffmpeg exists) in out_dir, atomically; returns notes."""
    from matplotlib import animation

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    anim = build_animation(result, frames=frames, fps=fps)
    notes = []
    targets = [("animation.gif", animation.PillowWriter(fps=fps))]
    if ffmpeg_available():
        targets.append(("animation.mp4", animation.FFMpegWriter(fps=fps)))
    else:
        notes.append("ffmpeg not found: wrote animation.gif only (install ffmpeg for animation.mp4)")
    for name, writer in targets:
        with atomic_path(out_dir / name, keep_extension=True) as tmp:
            anim.save(tmp, writer=writer)
        notes.append(f"wrote {out_dir / name}")
    return notes


def animate(result, sf=None, frames: int = 60, fps: int = 20):
    """An inline HTML (JavaScript) animation for notebooks; the HTML string without IPython."""
    html = build_animation(result, sf, frames=frames, fps=fps, dpi=70).to_jshtml()
    try:
        from IPython.display import HTML
    except ImportError:
        return html
    return HTML(html)
