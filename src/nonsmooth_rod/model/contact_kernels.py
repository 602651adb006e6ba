"""The one implementation of contact kinematics: one kernel per kind of contact.

A contact is a row of floats (its geometry, the columns C_* below) plus its kind and the (at
most two) bodies it touches. `kinematics_kernel(kind, row, body_a, body_b, q, v, hn, ht)`
returns (gap, Ḣ_N v, Ḣ_T v) and fills hn, ht: the Jacobian rows H_N, H_T restricted to the
bodies, six entries, (ẋ, ẏ, θ̇) of body a then of body b (zero when the obstacle is fixed).

Both users read these kernels: the compiled Moreau–Jean loop (through
`packing.contact_kinematics`, on the packed table, where numba compiles them in) and the
relation classes of model/contacts.py (their `kinematics`, used by the event-driven reference,
the phase location, the impacts' reports, ...), which call them as plain Python with their own
row (`_jit.jitable`: never a compile wait) — one source, so the two cannot drift apart.

Conventions: the normal n points from the obstacle (or body b) to the disk of body a; the
tangent is n turned by −90°, t = (n_y, −n_x) (a floor with normal +y has tangent +x);
the drifts are d/dt of H·v along q̇ = v at fixed v, so that g̈ = H_N a + Ḣ_N v.
"""
from __future__ import annotations

import math

from .._jit import jitable

KIND_DISK_ON_LINE, KIND_DISK_ON_DISK, KIND_DISK_ON_SEGMENT, KIND_SEGMENT_END_ON_EDGE = 0, 1, 2, 3
# A vertex (or disk) of body a on an edge of body b or of a fixed segment (model/collision.py);
# a fixed vertex (a segment's end) on an edge of body a.
KIND_VERTEX_ON_EDGE, KIND_FIXED_VERTEX_ON_EDGE = 4, 5
# Float columns of a contact row. A segment stores its end a in C_LINE_P*, its unit direction
# a → b in C_T*, its left normal in C_N* and its length in C_SEGMENT_LENGTH. A segment's end on
# a body's edge: the end point in C_LINE_P*, the edge's start in C_OFF_A*, its unit direction
# (body frame) in C_EDGE_T* and its length in C_SEGMENT_LENGTH.
(C_OFF_AX, C_OFF_AY, C_RADIUS_A, C_OFF_BX, C_OFF_BY, C_RADIUS_B, C_LINE_PX, C_LINE_PY, C_NX, C_NY, C_TX,
 C_TY, C_SURFACE_VELOCITY, C_MU_S, C_MU_D, C_RESTITUTION, C_SEGMENT_LENGTH, C_EDGE_TX, C_EDGE_TY) = range(19)
# A vertex on an edge (KIND_VERTEX_ON_EDGE, KIND_FIXED_VERTEX_ON_EDGE): the vertex in C_OFF_A*
# (body frame; a fixed vertex: world, in C_LINE_P*), the outward normals of its previous and
# next edges in C_CONE_1*, C_CONE_2* (its normal cone; the vertex owner's frame), whether it
# keeps a tie at coincident corners (C_TIE_WINS, 1 or 0), the deepest penetration still counted
# (C_DEPTH_LIMIT); the edge's start in C_OFF_B* and unit direction in C_EDGE_T* (the edge
# owner's frame; world when fixed), its length in C_SEGMENT_LENGTH.
C_CONE_1X, C_CONE_1Y, C_CONE_2X, C_CONE_2Y, C_TIE_WINS, C_DEPTH_LIMIT = range(19, 25)
# A vertex within SEAM_TOL × the edge's length of an end of the edge is at that end. An edge
# normal within FACE_TOL (a sine: 1°) of a boundary of the vertex's normal cone is on it: the
# vertex's edge and the edge face each other, and both of its ends may touch — counting only the
# nearer end of two faces tilted by less would drop a face's second support as it rocks (the far
# end, just outside its cone, is then farther than the near one by the tilt: no wrong contact).
SEAM_TOL, FACE_TOL = 1e-9, 0.0175
# A driven obstacle (model/motion.py): the motion moving it (−1: none, a float holding an index),
# the obstacle point C_LINE_P* at rest (C_LINE_P* itself is its place at the step's start) and its
# velocity (world frame) at the step's end and at its start, which the step subtracts from the
# contact's relative velocity at the end (the law) and at the start (activation, u_N before impact).
C_MOTION, C_BASE_PX, C_BASE_PY, C_OBSTACLE_VX, C_OBSTACLE_VY, C_OBSTACLE_START_VX, C_OBSTACLE_START_VY = range(25, 32)
# A vertex on an edge of a polygon: the outward normals of the edge's previous and next edges
# (the edge owner's frame; zero: no neighbour — a segment's side, a hand-declared edge). Of the
# edges a point has crossed, only the least penetrated one is its pair (separating axes, locally):
# a segment's end resting on a box's side is not also a deep contact on the box's top.
C_PREV_NX, C_PREV_NY, C_NEXT_NX, C_NEXT_NY = range(32, 36)
# A linear relation (Siconos' LagrangianLinearTIR): gap g0 + w_N·q and tangent row w_T, both
# constant, over the 6 coordinates (x, y, θ of body a, then of body b): w_N in C_LINEAR_N +
# 0..5, w_T in C_LINEAR_T + 0..5, g0 in C_LINEAR_GAP0 (a constant tangential drift is
# C_SURFACE_VELOCITY, as a belt's).
KIND_LINEAR = 6
C_LINEAR_N, C_LINEAR_T, C_LINEAR_GAP0 = 36, 42, 48
N_CONTACT_COLUMNS = 49


@jitable
def _body_point(row, body, q, ox_col, oy_col):
    """The disk centre's offset d from the body's centre of mass, world frame."""
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    ox, oy = row[ox_col], row[oy_col]
    return c * ox - s * oy, s * ox + c * oy


@jitable
def _fill_rows(hn, ht, side, nx, ny, rho_x, rho_y, sign):
    """One body's (ẋ, ẏ, θ̇) entries of H_N and H_T for lever arm ρ to the contact point."""
    k = 3 * side
    tx, ty = ny, -nx
    hn[k], hn[k + 1], hn[k + 2] = sign * nx, sign * ny, sign * (rho_x * ny - rho_y * nx)
    ht[k], ht[k + 1], ht[k + 2] = sign * tx, sign * ty, sign * (rho_x * ty - rho_y * tx)


@jitable
def _clear_side(hn, ht, side):
    for d in range(3 * side, 3 * side + 3):
        hn[d] = 0.0
        ht[d] = 0.0


@jitable
def _on_fixed_normal(row, body, q, v, hn, ht, nx, ny, px, py):
    """A disk of body a against a fixed plane through p with normal n (a line, a segment's
    interior): (gap, Ḣ_N v, Ḣ_T v). The lever arm turns with the body, the plane does not."""
    j = 3 * body
    dx, dy = _body_point(row, body, q, C_OFF_AX, C_OFF_AY)
    r = row[C_RADIUS_A]
    _fill_rows(hn, ht, 0, nx, ny, dx - r * nx, dy - r * ny, 1.0)
    _clear_side(hn, ht, 1)
    om = v[j + 2]
    gap = nx * (q[j] + dx - px) + ny * (q[j + 1] + dy - py) - r
    return gap, -om * om * (dx * nx + dy * ny), -om * om * (dx * ny - dy * nx)


@jitable
def _centre_velocity(body, dx, dy, v):
    j = 3 * body
    om = v[j + 2]
    return v[j] - om * dy, v[j + 1] + om * dx


@jitable
def _disk_on_disk(row, body_a, body_b, q, v, hn, ht):
    ia, ib = 3 * body_a, 3 * body_b
    dax, day = _body_point(row, body_a, q, C_OFF_AX, C_OFF_AY)
    dbx, dby = _body_point(row, body_b, q, C_OFF_BX, C_OFF_BY)
    ex, ey = q[ia] + dax - q[ib] - dbx, q[ia + 1] + day - q[ib + 1] - dby
    dist = math.sqrt(ex * ex + ey * ey)
    if dist == 0.0:  # coincident centres: no normal; the caller reports it
        return math.nan, math.nan, math.nan
    nx, ny = ex / dist, ey / dist
    ra, rb = row[C_RADIUS_A], row[C_RADIUS_B]
    _fill_rows(hn, ht, 0, nx, ny, dax - ra * nx, day - ra * ny, 1.0)
    _fill_rows(hn, ht, 1, nx, ny, dbx + rb * nx, dby + rb * ny, -1.0)
    wax, way = _centre_velocity(body_a, dax, day, v)
    wbx, wby = _centre_velocity(body_b, dbx, dby, v)
    om_a, om_b = v[ia + 2], v[ib + 2]
    # The centres' centripetal accelerations, plus the turn of n (and t) with the relative
    # velocity w of the centres: ṅ = (w·t) t / dist, ṫ = −(w·t) n / dist.
    acc_x = -om_a * om_a * dax + om_b * om_b * dbx
    acc_y = -om_a * om_a * day + om_b * om_b * dby
    drift_n, drift_t = _turning_drifts(wax - wbx, way - wby, nx, ny, dist, acc_x, acc_y)
    return dist - ra - rb, drift_n, drift_t


@jitable
def _turning_drifts(wx, wy, nx, ny, dist, acc_x, acc_y):
    """(Ḣ_N v, Ḣ_T v) of a normal along the centres' line (length dist, relative velocity w)."""
    w_n, w_t = wx * nx + wy * ny, wx * ny - wy * nx
    return acc_x * nx + acc_y * ny + w_t * w_t / dist, acc_x * ny - acc_y * nx - w_t * w_n / dist


@jitable
def _disk_on_segment(row, body, q, v, hn, ht):
    """A disk against the feature of a fixed segment nearest its centre: the interior (the
    segment's normal on the disk's side) or an end point (normal from the end to the centre)."""
    j = 3 * body
    dx, dy = _body_point(row, body, q, C_OFF_AX, C_OFF_AY)
    ax, ay, ex, ey = row[C_LINE_PX], row[C_LINE_PY], row[C_TX], row[C_TY]
    cx, cy = q[j] + dx - ax, q[j + 1] + dy - ay
    along = cx * ex + cy * ey
    if 0.0 <= along <= row[C_SEGMENT_LENGTH]:
        nx, ny = row[C_NX], row[C_NY]
        if cx * nx + cy * ny < 0.0:  # the disk is on the other side
            nx, ny = -nx, -ny
        return _on_fixed_normal(row, body, q, v, hn, ht, nx, ny, ax, ay)
    end = min(max(along, 0.0), row[C_SEGMENT_LENGTH])
    return _on_fixed_point(body, dx, dy, row[C_RADIUS_A], ax + end * ex, ay + end * ey, q, v, hn, ht)


@jitable
def _on_fixed_point(body, dx, dy, r, px, py, q, v, hn, ht):
    """A disk of radius r centred at offset d (world frame) from body a's centre of mass against
    the fixed point p: the normal from p to the centre."""
    j = 3 * body
    rx, ry = q[j] + dx - px, q[j + 1] + dy - py
    dist = math.sqrt(rx * rx + ry * ry)
    if dist == 0.0:
        return math.nan, math.nan, math.nan
    nx, ny = rx / dist, ry / dist
    _fill_rows(hn, ht, 0, nx, ny, dx - r * nx, dy - r * ny, 1.0)
    _clear_side(hn, ht, 1)
    wx, wy = _centre_velocity(body, dx, dy, v)
    om = v[j + 2]
    drift_n, drift_t = _turning_drifts(wx, wy, nx, ny, dist, -om * om * dx, -om * om * dy)
    return dist - r, drift_n, drift_t


@jitable
def _segment_end_on_edge(row, body, q, v, hn, ht):
    """A segment's end point p against an edge of body a (start e, unit direction τ, body frame;
    the body on its left, so its outward normal is τ turned by −90°). While p lies along the
    edge, the normal is the edge's inward normal and the touching material point is the one at p;
    beyond the edge's ends, the edge's end point nearest p touches it (the body's corner)."""
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    ex, ey = _body_point(row, body, q, C_OFF_AX, C_OFF_AY)
    tx, ty = c * row[C_EDGE_TX] - s * row[C_EDGE_TY], s * row[C_EDGE_TX] + c * row[C_EDGE_TY]
    px, py = row[C_LINE_PX], row[C_LINE_PY]
    along = (px - q[j] - ex) * tx + (py - q[j + 1] - ey) * ty
    if not 0.0 <= along <= row[C_SEGMENT_LENGTH]:
        end = min(max(along, 0.0), row[C_SEGMENT_LENGTH])
        return _on_fixed_point(body, ex + end * tx, ey + end * ty, 0.0, px, py, q, v, hn, ht)
    nx, ny = -ty, tx  # inward: from the obstacle's point into the body
    rho_x, rho_y = px - q[j], py - q[j + 1]
    _fill_rows(hn, ht, 0, nx, ny, rho_x, rho_y, 1.0)
    _clear_side(hn, ht, 1)
    # The edge turns with the body and the touching material point changes as the body moves:
    # d/dt (n·v + ω ρ×n) = 2 ω n×v + ω² ρ·n, likewise for t.
    om, vx, vy = v[j + 2], v[j], v[j + 1]
    gap = -(nx * (px - q[j] - ex) + ny * (py - q[j + 1] - ey))
    return (gap, 2.0 * om * (nx * vy - ny * vx) + om * om * (rho_x * nx + rho_y * ny),
            2.0 * om * (ny * vy + nx * vx) + om * om * (rho_x * ny - rho_y * nx))


@jitable
def _frame(body, q, v, row, ox_col, oy_col):
    """(cos θ, sin θ, world point of the body-frame offset in the row, its lever, velocity and ω
    of the body) — the world itself (offset = world point, at rest) for body −1."""
    if body < 0:
        return 1.0, 0.0, row[ox_col], row[oy_col], 0.0, 0.0, 0.0, 0.0, 0.0
    j = 3 * body
    c, s = math.cos(q[j + 2]), math.sin(q[j + 2])
    rx, ry = c * row[ox_col] - s * row[oy_col], s * row[ox_col] + c * row[oy_col]
    return c, s, q[j] + rx, q[j + 1] + ry, rx, ry, v[j], v[j + 1], v[j + 2]


@jitable
def _vertex_feature_valid(row, along, length, dx, dy, ca, sa):
    """The feature-pair rule of a vertex (radius 0) on an edge: −n (dx, dy) in the vertex's
    normal cone; where it lies on a boundary of the cone, the face-to-face edges must overlap,
    and a vertex at the edge's end (a corner on a corner) keeps the tie only if C_TIE_WINS."""
    n1x, n1y = ca * row[C_CONE_1X] - sa * row[C_CONE_1Y], sa * row[C_CONE_1X] + ca * row[C_CONE_1Y]
    n2x, n2y = ca * row[C_CONE_2X] - sa * row[C_CONE_2Y], sa * row[C_CONE_2X] + ca * row[C_CONE_2Y]
    c1, c2 = n1x * dy - n1y * dx, dx * n2y - dy * n2x
    if c1 < -FACE_TOL or c2 < -FACE_TOL:
        return False
    tol = SEAM_TOL * length
    if c1 <= FACE_TOL and n1x * dx + n1y * dy > 0.0:  # the previous edge face to face: it runs along +τ
        if along > length - tol:
            return False
        if along < tol and row[C_TIE_WINS] == 0.0:
            return False
    if c2 <= FACE_TOL and n2x * dx + n2y * dy > 0.0:  # the next edge face to face: it runs along −τ
        if along < tol:
            return False
        if along > length - tol and row[C_TIE_WINS] == 0.0:
            return False
    return True


@jitable
def _in_cone(row, dx, dy, ca, sa):
    """Whether the direction d lies in the vertex's normal cone (within FACE_TOL)."""
    return _cone_margin(row, dx, dy, ca, sa) >= 0.0


@jitable
def _cone_margin(row, dx, dy, ca, sa):
    """How far (a sine) the direction d lies inside the vertex's normal cone widened by FACE_TOL:
    ≥ 0 inside (the sign of a sum of two floats is the sign of the exact sum: the same test as
    comparing each side with −FACE_TOL)."""
    n1x, n1y = ca * row[C_CONE_1X] - sa * row[C_CONE_1Y], sa * row[C_CONE_1X] + ca * row[C_CONE_1Y]
    n2x, n2y = ca * row[C_CONE_2X] - sa * row[C_CONE_2Y], sa * row[C_CONE_2X] + ca * row[C_CONE_2Y]
    return min(n1x * dy - n1y * dx, dx * n2y - dy * n2x) + FACE_TOL


@jitable
def vertex_cone_margin(row, point_body, edge_body, q):
    """The cone rule's margin (_cone_margin, a sine) of a vertex–edge row at q: the kernel never
    counts the pair where it is < 0 (+inf for a disk: no cone rule). A difference of products of
    unit directions turned by the two bodies' angles: it changes by at most their relative turn
    (the broad phase's kept list leaves out the pairs it keeps below 0, moreau_jean_loop._keep_near)."""
    if row[C_RADIUS_A] != 0.0:
        return math.inf
    ca, sa = _frame(point_body, q, q, row, C_OFF_AX, C_OFF_AY)[:2]
    cb, sb = _frame(edge_body, q, q, row, C_OFF_BX, C_OFF_BY)[:2]
    tx, ty = cb * row[C_EDGE_TX] - sb * row[C_EDGE_TY], sb * row[C_EDGE_TX] + cb * row[C_EDGE_TY]
    return _cone_margin(row, -ty, tx, ca, sa)


@jitable
def _least_penetrated(row, dx, dy, height, tx, ty, length, cb, sb, ca, sa, is_vertex):
    """Whether the point at d = P − E (world axes; `height` its signed distance above the edge)
    is no deeper behind this edge than behind either neighbouring edge it could touch instead
    (a vertex: the neighbour's normal, turned around, in its cone; a disk: any). The previous
    edge passes through the edge's start E, the next one through its end E + length τ."""
    tol = SEAM_TOL * length
    return not (_neighbour_wins(row, C_PREV_NX, C_PREV_NY, dx, dy, height + tol, cb, sb, ca, sa, is_vertex)
                or _neighbour_wins(row, C_NEXT_NX, C_NEXT_NY, dx - length * tx, dy - length * ty, height + tol,
                                   cb, sb, ca, sa, is_vertex))


@jitable
def _neighbour_wins(row, x_col, y_col, dx, dy, height, cb, sb, ca, sa, is_vertex):
    """Whether the point at d from a point of a neighbouring edge is higher above it than `height`."""
    mx, my = row[x_col], row[y_col]
    if mx == 0.0 and my == 0.0:
        return False
    mx, my = cb * mx - sb * my, sb * mx + cb * my
    return mx * dx + my * dy > height and (not is_vertex or _in_cone(row, -mx, -my, ca, sa))


@jitable
def _vertex_on_edge(row, point_body, edge_body, q, v, hn, ht):
    """A vertex (or a disk of radius C_RADIUS_A) of `point_body` (−1: fixed) on a straight edge
    of `edge_body` (−1: fixed), the edge's outward normal n = τ turned by −90° (a CCW outline).
    Gap n·(P − E) − r; the edge's touching point is the foot Q = E + (τ·(P − E)) τ. An infinite
    gap: the pair is not the touching one (the foot beyond the edge, a wrong cone, too deep)."""
    gap, drift_n, drift_t, margin = _vertex_on_edge_rows(row, point_body, edge_body, q, v, hn, ht, True)
    if not margin >= 0.0:
        return math.inf, 0.0, 0.0
    return gap, drift_n, drift_t


@jitable
def _pair_margin(row, along, gap, dx, dy, tx, ty, nx, ny, cb, sb, ca, sa):
    """How far inside the region where the vertex–edge pair is the touching one (m; at the cone,
    a sine): ≥ 0 inside. Continuous in the foot's place, the depth and the cone; the discrete
    rules (face-to-face seams, the least penetrated edge) put it just below 0."""
    r, length = row[C_RADIUS_A], row[C_SEGMENT_LENGTH]
    tol = SEAM_TOL * length
    margin = min(along + tol, length + tol - along, gap + row[C_DEPTH_LIMIT])
    if r == 0.0:
        margin = min(margin, _cone_margin(row, -nx, -ny, ca, sa))
    if margin >= 0.0 and r == 0.0 and not _vertex_feature_valid(row, along, length, -nx, -ny, ca, sa):
        return -_TINY_MARGIN
    if margin >= 0.0 and gap < 0.0 and not _least_penetrated(row, dx, dy, gap + r, tx, ty, length, cb, sb, ca, sa,
                                                             r == 0.0):
        return -_TINY_MARGIN
    return margin


# A margin just below zero: the pair is outside by a discrete rule, not by a distance.
_TINY_MARGIN = 1e-300


@jitable
def vertex_on_edge_region(row, point_body, edge_body, q, v, hn, ht):
    """(gap, Ḣ_N v, Ḣ_T v, margin) of a vertex on an edge, whether or not the pair is the touching
    one: the gap finite, the margin `_pair_margin` (the kernel's rule: counted iff margin ≥ 0;
    below 0 the drifts are left at 0).
    The event-driven reference locates where a contact enters or leaves its region from it."""
    return _vertex_on_edge_rows(row, point_body, edge_body, q, v, hn, ht, False)


@jitable
def _vertex_on_edge_rows(row, point_body, edge_body, q, v, hn, ht, counted_only):
    """vertex_on_edge_region; with `counted_only`, a pair outside its region (margin < 0) gets
    zero rows, computed before its rows and drifts are: most vertex–edge candidates of two
    touching boxes are not the touching pair, and the kernel reads nothing else of them."""
    ca, sa, px, py, rpx, rpy, vax, vay, om_a = _frame(point_body, q, v, row, C_OFF_AX, C_OFF_AY)
    if point_body < 0:
        px, py = row[C_LINE_PX], row[C_LINE_PY]
    cb, sb, ex, ey, rex, rey, vbx, vby, om_b = _frame(edge_body, q, v, row, C_OFF_BX, C_OFF_BY)
    tx, ty = cb * row[C_EDGE_TX] - sb * row[C_EDGE_TY], sb * row[C_EDGE_TX] + cb * row[C_EDGE_TY]
    nx, ny = ty, -tx
    r = row[C_RADIUS_A]
    dx, dy = px - ex, py - ey
    along = dx * tx + dy * ty
    gap = dx * nx + dy * ny - r
    margin = _pair_margin(row, along, gap, dx, dy, tx, ty, nx, ny, cb, sb, ca, sa)
    if counted_only and not margin >= 0.0:
        _clear_side(hn, ht, 0)
        _clear_side(hn, ht, 1)
        return gap, 0.0, 0.0, margin
    rqx, rqy = rex + along * tx, rey + along * ty
    if point_body >= 0:
        _fill_rows(hn, ht, 0, nx, ny, rpx - r * nx, rpy - r * ny, 1.0)
        if edge_body >= 0:
            _fill_rows(hn, ht, 1, nx, ny, rqx, rqy, -1.0)
        else:
            _clear_side(hn, ht, 1)
    else:
        _fill_rows(hn, ht, 0, nx, ny, rqx, rqy, -1.0)
        _clear_side(hn, ht, 1)
    if not margin >= 0.0:
        return gap, 0.0, 0.0, margin  # not the touching pair: no drifts (the kernel's gap is infinite)
    # w: velocity of P's material point relative to E's; at fixed v the levers turn, so
    # d/dt Ṗ = −ω_a² r_P and d/dt Ė = −ω_b² r_E, while n turns by ω_b τ and τ by −ω_b n.
    wx, wy = vax - om_a * rpy - vbx + om_b * rey, vay + om_a * rpx - vby - om_b * rex
    accx, accy = -om_a * om_a * rpx + om_b * om_b * rex, -om_a * om_a * rpy + om_b * om_b * rey
    drift_n = -om_b * om_b * (gap + r) + 2.0 * om_b * (tx * wx + ty * wy) + nx * accx + ny * accy
    drift_t = om_b * (nx * wx + ny * wy) + ny * accx - nx * accy
    return gap, drift_n, drift_t, margin


@jitable
def _linear_relation(row, body_a, body_b, q, hn, ht):
    """g0 + w_N·q with the constant rows w_N, w_T: no drift (Ḣ = 0)."""
    gap = row[C_LINEAR_GAP0]
    for side in range(2):
        body = body_a if side == 0 else body_b
        for d in range(3):
            k = 3 * side + d
            hn[k], ht[k] = row[C_LINEAR_N + k], row[C_LINEAR_T + k]
            if body >= 0:
                gap += hn[k] * q[3 * body + d]
    return gap, 0.0, 0.0


@jitable
def obstacle_velocity(nx, ny, tx, ty, wx, wy, surface):
    """(w_N, w_T): an obstacle's velocity w (a driven obstacle's) along the contact's normal n and
    tangent t, plus a belt's surface velocity along t — what the relative velocity subtracts from
    H v. Scalars: the compiled loop reads them from its tables without making array views."""
    return nx * wx + ny * wy, tx * wx + ty * wy + surface


@jitable
def kinematics_kernel(kind, row, body_a, body_b, q, v, hn, ht):
    """(gap, Ḣ_N v, Ḣ_T v) of one contact; fills its 6-entry Jacobian rows hn, ht. A nan gap:
    the normal is undefined (coincident centres)."""
    if kind == KIND_DISK_ON_LINE:
        return _on_fixed_normal(row, body_a, q, v, hn, ht, row[C_NX], row[C_NY], row[C_LINE_PX], row[C_LINE_PY])
    if kind == KIND_DISK_ON_SEGMENT:
        return _disk_on_segment(row, body_a, q, v, hn, ht)
    if kind == KIND_SEGMENT_END_ON_EDGE:
        return _segment_end_on_edge(row, body_a, q, v, hn, ht)
    if kind == KIND_VERTEX_ON_EDGE:
        return _vertex_on_edge(row, body_a, body_b, q, v, hn, ht)
    if kind == KIND_FIXED_VERTEX_ON_EDGE:
        return _vertex_on_edge(row, -1, body_a, q, v, hn, ht)
    if kind == KIND_LINEAR:
        return _linear_relation(row, body_a, body_b, q, hn, ht)
    return _disk_on_disk(row, body_a, body_b, q, v, hn, ht)
