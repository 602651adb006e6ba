"""The benchmark's scenes stepped by other engines, timed the same way as ours (process time per
step, median of repeats): MuJoCo's `mj_step` and PyBullet's `stepSimulation`, each optional
(`pip install "nonsmooth-rod[bench]"`). Both are 3-D soft-contact engines: the balls are spheres
on a plane, the planar motion is not enforced, and their friction has one coefficient — they
do less than our step, which resolves μs/μd exactly; the comparison is of cost only.

A row is N balls of radius R on the floor, 1 mm apart, the first rolling at 1 m/s into the
others; a pile is `rows` rows of balls stacked in a triangle on the floor.
"""
from __future__ import annotations

import statistics
import time


def _median_step_us(step, reset, steps: int, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        reset()
        t0 = time.process_time()
        for _ in range(steps):
            step()
        times.append((time.process_time() - t0) / steps * 1e6)
    return statistics.median(times)


def mujoco_step_us(centres, radius, mass, h, steps, repeats, first_speed=1.0):
    """mj_step per step, or None when MuJoCo is not installed."""
    try:
        import mujoco
    except ImportError:
        return None
    bodies = "".join(f'<body pos="{x} 0 {z}"><freejoint/><geom type="sphere" size="{radius}" mass="{mass}"/></body>'
                     for x, z in centres)
    xml = (f'<mujoco><option timestep="{h}"/><worldbody><geom type="plane" size="50 50 0.1"/>{bodies}'
           "</worldbody></mujoco>")
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)

    def reset():
        mujoco.mj_resetData(model, data)
        data.qvel[0] = first_speed

    return _median_step_us(lambda: mujoco.mj_step(model, data), reset, steps, repeats)


def pybullet_step_us(centres, radius, mass, h, steps, repeats, first_speed=1.0):
    """stepSimulation per step (DIRECT mode, no GUI), or None when PyBullet is not installed."""
    try:
        import pybullet
    except ImportError:
        return None
    client = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
        pybullet.setTimeStep(h, physicsClientId=client)
        plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client)
        pybullet.createMultiBody(0, plane, physicsClientId=client)
        sphere = pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=radius, physicsClientId=client)
        balls = [pybullet.createMultiBody(mass, sphere, basePosition=[x, 0, z], physicsClientId=client)
                 for x, z in centres]

        def reset():
            for ball, (x, z) in zip(balls, centres):
                pybullet.resetBasePositionAndOrientation(ball, [x, 0, z], [0, 0, 0, 1], physicsClientId=client)
                pybullet.resetBaseVelocity(ball, [0, 0, 0], [0, 0, 0], physicsClientId=client)
            pybullet.resetBaseVelocity(balls[0], [first_speed, 0, 0], [0, 0, 0], physicsClientId=client)

        return _median_step_us(lambda: pybullet.stepSimulation(physicsClientId=client), reset, steps, repeats)
    finally:
        pybullet.disconnect(physicsClientId=client)
