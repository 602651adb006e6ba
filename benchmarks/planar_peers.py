"""The rows and piles of `toys/stacks.py` stepped by other engines, planar where the engine allows,
timed as ours (process time per step, median of repeats). Each peer is optional: install them in
a separate virtual environment, not in the project's dependencies::

    python3 -m venv /work/bench-venv --system-site-packages
    /work/bench-venv/bin/pip install mujoco pybullet pymunk

Every peer gets the same geometry (balls of radius R, mass m, inertia 0.4 m R²), the same
friction coefficient (one μ: their laws have no μs/μd — our μs is given), restitution 0, gravity
9.81, h and initial state, and finds its contacts itself (as ours declares every pair and lets
its broad phase drop those out of reach). Their settings, stated so the comparison is fair both
ways (`PEER_SETTINGS`):

* MuJoCo: planar — each ball a body with slide x, slide z and hinge y joints; spheres on a plane
  floor, plane walls; default solver (Newton, 100 iterations, tolerance 1e-8), pyramidal cone,
  condim 3, soft contacts (solref 0.02 1: the default), `mj_step`.
* PyBullet: 3-D spheres on a plane with box walls (no planar constraint: the scene stays in its
  plane by symmetry), default solver (sequential impulses, 50 iterations, ERP), `stepSimulation`.
* pymunk (Chipmunk2D): planar, circles on static segments, `space.iterations` 10 (default) and
  100, friction √μ per shape (Chipmunk multiplies the two shapes'), `space.step(h)`.

None of them solves the exact two-coefficient law, and MuJoCo and PyBullet are soft-contact
engines (a resting pile sinks into its floor by their penetration allowance): the comparison is
of cost only.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/ for other_engines
from other_engines import _median_step_us  # noqa: E402  (one timing loop for every peer)

PEER_SETTINGS = {
    "mujoco": "planar (slide x, slide z, hinge y); Newton solver, 100 iterations, tol 1e-8, pyramidal cone, "
              "condim 3, default solref/solimp",
    "bullet": "3-D spheres, box walls, DIRECT mode; default SI solver, 50 iterations",
    "pymunk10": ("Chipmunk2D, space.iterations = 10 (default), collision_slop 1e-4 m (default 0.1), "
                 "friction sqrt(mu) per shape"),
    "pymunk100": "Chipmunk2D, space.iterations = 100",
}


def mujoco_planar_step_us(scene, h, steps, repeats):
    """mj_step per step on the planar model, or None when MuJoCo is not installed. `scene`:
    dict with centres [(x, y)], radius, mass, mu, walls (x_left, x_right) or None, v0 [(vx, vy, w)]."""
    try:
        import mujoco
    except ImportError:
        return None
    r, m, mu = scene["radius"], scene["mass"], scene["mu"]
    bodies = "".join(
        f'<body pos="{x} 0 {y}"><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 0 1"/>'
        f'<joint type="hinge" axis="0 1 0"/><geom type="sphere" size="{r}" mass="{m}"/></body>'
        for x, y in scene["centres"])
    walls = ""
    if scene["walls"]:
        left, right = scene["walls"]
        walls = (f'<geom type="plane" size="50 50 0.1" pos="{left} 0 0" zaxis="1 0 0"/>'
                 f'<geom type="plane" size="50 50 0.1" pos="{right} 0 0" zaxis="-1 0 0"/>')
    xml = (f'<mujoco><option timestep="{h}"/><default><geom friction="{mu} 0.005 0.0001" condim="3"/></default>'
           f'<worldbody><geom type="plane" size="50 50 0.1"/>{walls}{bodies}</worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def reset():
        mujoco.mj_resetData(model, data)
        for b, (vx, vy, w) in enumerate(scene["v0"]):
            data.qvel[3 * b: 3 * b + 3] = (vx, vy, -w)  # our ω about +z is −ω about MuJoCo's +y

    return _median_step_us(lambda: mujoco.mj_step(model, data), reset, steps, repeats)


def pybullet_step_us(scene, h, steps, repeats):
    """stepSimulation per step (DIRECT mode), or None when PyBullet is not installed."""
    try:
        import pybullet as pb
    except ImportError:
        return None
    client = pb.connect(pb.DIRECT)
    try:
        r, m, mu = scene["radius"], scene["mass"], scene["mu"]
        pb.setGravity(0, 0, -9.81, physicsClientId=client)
        pb.setTimeStep(h, physicsClientId=client)
        fixed = [pb.createMultiBody(0, pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=client),
                                    physicsClientId=client)]
        if scene["walls"]:
            box = pb.createCollisionShape(pb.GEOM_BOX, halfExtents=[0.5, 5, 5], physicsClientId=client)
            left, right = scene["walls"]
            fixed += [pb.createMultiBody(0, box, basePosition=[left - 0.5, 0, 0], physicsClientId=client),
                      pb.createMultiBody(0, box, basePosition=[right + 0.5, 0, 0], physicsClientId=client)]
        sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=r, physicsClientId=client)
        balls = [pb.createMultiBody(m, sphere, basePosition=[x, 0, y], physicsClientId=client)
                 for x, y in scene["centres"]]
        for body in fixed + balls:
            pb.changeDynamics(body, -1, lateralFriction=mu, restitution=0.0, physicsClientId=client)

        def reset():
            for ball, (x, y), (vx, vy, w) in zip(balls, scene["centres"], scene["v0"]):
                pb.resetBasePositionAndOrientation(ball, [x, 0, y], [0, 0, 0, 1], physicsClientId=client)
                pb.resetBaseVelocity(ball, [vx, 0, vy], [0, -w, 0], physicsClientId=client)

        return _median_step_us(lambda: pb.stepSimulation(physicsClientId=client), reset, steps, repeats)
    finally:
        pb.disconnect(physicsClientId=client)


def _pymunk_space(pymunk, iterations, lines, friction):
    """A pymunk space with `iterations`, gravity, a collision slop of 0.1 mm (its default, 0.1, lets
    shapes overlap by up to 10 cm: not the same scene) and the static segments `lines` ((a, b) pairs)."""
    space = pymunk.Space()
    space.iterations, space.collision_slop, space.gravity = iterations, 1e-4, (0.0, -9.81)
    for a, b in lines:
        segment = pymunk.Segment(space.static_body, a, b, 0.0)
        segment.friction, segment.elasticity = friction, 0.0
        space.add(segment)
    return space


def pymunk_step_us(scene, h, steps, repeats, iterations):
    """space.step per step with `iterations`, or None when pymunk is not installed."""
    try:
        import pymunk
    except ImportError:
        return None
    r, m, mu = scene["radius"], scene["mass"], scene["mu"]
    friction = math.sqrt(mu)  # Chipmunk's pair friction is the product of the shapes'
    holder = {}

    def reset():
        lines = [((-50.0, 0.0), (50.0, 0.0))]
        if scene["walls"]:
            left, right = scene["walls"]
            lines += [((left, 0.0), (left, 50.0)), ((right, 0.0), (right, 50.0))]
        space = _pymunk_space(pymunk, iterations, lines, friction)
        for (x, y), (vx, vy, w) in zip(scene["centres"], scene["v0"]):
            body = pymunk.Body(m, 0.4 * m * r * r)
            body.position, body.velocity, body.angular_velocity = (x, y), (vx, vy), w
            circle = pymunk.Circle(body, r)
            circle.friction, circle.elasticity = friction, 0.0
            space.add(body, circle)
        holder["space"] = space

    return _median_step_us(lambda: holder["space"].step(h), reset, steps, repeats)


def peers_step_us(scene, h, steps, repeats):
    """[(peer, µs per step)] of every installed peer on `scene` (see mujoco_planar_step_us)."""
    out = []
    for name, cost in (("mujoco", lambda: mujoco_planar_step_us(scene, h, steps, repeats)),
                       ("bullet", lambda: pybullet_step_us(scene, h, steps, repeats)),
                       ("pymunk10", lambda: pymunk_step_us(scene, h, steps, repeats, 10)),
                       ("pymunk100", lambda: pymunk_step_us(scene, h, steps, repeats, 100))):
        us = cost()
        if us is not None:
            out.append((name, us))
    return out


# Boxes (bench_shapes.py): a scene is a dict with boxes [(x, y, θ, vx, vy, ω)], width, height,
# mass, mu (box–box), mu_line (box–line), lines [(point, angle)] (our Line: normal = the tangent
# turned by +90°) and depth (MuJoCo's out-of-plane half-thickness of a box).
BOX_PEER_SETTINGS = {
    "mujoco": "planar (slide x, slide z, hinge y); box geoms (half-depth 0.05 m out of plane), plane floor and "
              "walls; Newton, 100 iterations, tol 1e-8, pyramidal cone, condim 3, default solref/solimp; one "
              "friction per pair (MuJoCo takes the larger of the two geoms': set per geom)",
    "pymunk10": "Chipmunk2D boxes (Poly.create_box, radius 0) on static segments, space.iterations = 10 (default), "
                "collision_slop 1e-4 m (default 0.1: a tenth of a metre of overlap allowed), friction sqrt(mu) "
                "per shape",
    "pymunk100": "as pymunk10 with space.iterations = 100",
}


def _line_ends(point, angle, half=50.0):
    c, s = math.cos(angle), math.sin(angle)
    return (point[0] - half * c, point[1] - half * s), (point[0] + half * c, point[1] + half * s)


def mujoco_boxes_step_us(scene, h, steps, repeats):
    """mj_step per step on planar boxes, or None when MuJoCo is not installed."""
    try:
        import mujoco
    except ImportError:
        return None
    w, ht, d, m = scene["width"] / 2, scene["height"] / 2, scene["depth"], scene["mass"]
    bodies = "".join(
        f'<body pos="{x} 0 {y}" quat="{math.cos(-th / 2)} 0 {math.sin(-th / 2)} 0"><joint type="slide" axis="1 0 0"/>'
        f'<joint type="slide" axis="0 0 1"/><joint type="hinge" axis="0 1 0"/>'
        f'<geom type="box" size="{w} {d} {ht}" mass="{m}" friction="{scene["mu"]} 0.005 0.0001"/></body>'
        for x, y, th, *_ in scene["boxes"])
    planes = "".join(
        f'<geom type="plane" size="50 50 0.1" pos="{p[0]} 0 {p[1]}" zaxis="{-math.sin(a)} 0 {math.cos(a)}" '
        f'friction="{scene["mu_line"]} 0.005 0.0001"/>' for p, a in scene["lines"])
    xml = (f'<mujoco><option timestep="{h}"/><default><geom condim="3"/></default>'
           f'<worldbody>{planes}{bodies}</worldbody></mujoco>')
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def reset():
        mujoco.mj_resetData(model, data)
        for b, (*_, vx, vy, om) in enumerate(scene["boxes"]):
            data.qvel[3 * b: 3 * b + 3] = (vx, vy, -om)  # our ω about +z is −ω about MuJoCo's +y

    return _median_step_us(lambda: mujoco.mj_step(model, data), reset, steps, repeats)


def pymunk_boxes_step_us(scene, h, steps, repeats, iterations):
    """space.step per step on boxes with `iterations`, or None when pymunk is not installed."""
    try:
        import pymunk
    except ImportError:
        return None
    w, ht, m = scene["width"], scene["height"], scene["mass"]
    holder = {}

    def reset():
        space = _pymunk_space(pymunk, iterations, [_line_ends(point, angle) for point, angle in scene["lines"]],
                              scene["mu_line"] / math.sqrt(scene["mu"]))
        for x, y, th, vx, vy, om in scene["boxes"]:
            body = pymunk.Body(m, pymunk.moment_for_box(m, (w, ht)))
            body.position, body.angle, body.velocity, body.angular_velocity = (x, y), th, (vx, vy), om
            box = pymunk.Poly.create_box(body, (w, ht), 0.0)
            box.friction, box.elasticity = math.sqrt(scene["mu"]), 0.0
            space.add(body, box)
        holder["space"] = space

    return _median_step_us(lambda: holder["space"].step(h), reset, steps, repeats)


def box_peers_step_us(scene, h, steps, repeats):
    """[(peer, µs per step)] of every installed peer on a boxes `scene`."""
    out = []
    for name, cost in (("mujoco", lambda: mujoco_boxes_step_us(scene, h, steps, repeats)),
                       ("pymunk10", lambda: pymunk_boxes_step_us(scene, h, steps, repeats, 10)),
                       ("pymunk100", lambda: pymunk_boxes_step_us(scene, h, steps, repeats, 100))):
        us = cost()
        if us is not None:
            out.append((name, us))
    return out
