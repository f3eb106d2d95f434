"""numpy-spheres' engine calls: plain data in and out, numpy only (a repro script holds them)."""

import itertools

import numpy as np

from adapters.shared.scene import scene_answer, step_and_record


def pair(a_center, a_radius, b_center, b_radius):
    return np.array(b_center) - np.array(a_center), a_radius + b_radius


def detect(built):
    offset, radii = built
    length = float(np.linalg.norm(offset))
    normal = tuple(float(x) for x in offset / length) if length else "coincident centres"
    return {"hit": length < radii, "distance": length - radii, "normal": normal}


def scene(bodies, restitution, dt, gravity, walls, steps, record_every, **_):
    return {"x": np.array([b[0] for b in bodies]), "v": np.array([b[3] for b in bodies]),
            "bodies": bodies, "e": restitution, "dt": dt, "gravity": gravity,
            "walls": walls, "steps": steps, "record_every": record_every}


def step_scene(built):
    x, v, dt, bodies = built["x"], built["v"], built["dt"], built["bodies"]

    def step():
        v[:] += np.array(built["gravity"]) * dt
        x[:] += v * dt
        for i, j in itertools.combinations(range(len(bodies)), 2):
            d = x[j] - x[i]
            length = float(np.linalg.norm(d))
            closing = float((v[i] - v[j]) @ d) / length if length else 0.0
            if length < bodies[i][1] + bodies[j][1] and closing > 0:
                impulse = (1 + built["e"]) * closing / (1 / bodies[i][2] + 1 / bodies[j][2])
                v[i] -= impulse / bodies[i][2] * d / length
                v[j] += impulse / bodies[j][2] * d / length

    wall_s, records = step_and_record(step, lambda: (x.tolist(), v.tolist()),
                                      built["steps"], built["record_every"])
    return scene_answer(bodies, built["gravity"], built["walls"], dt, built["steps"],
                        (x.tolist(), v.tolist()), records, wall_s)
