"""Two-level instancing: one 'tree' prototype placed 64 times, lit by a sun and sky.

`kauri render scenes/instanced_forest.py -o forest.exr`
"""
import math

import numpy as np

import kauri


def build():
    s = kauri.Scene()
    ground = np.array([[-20, 0, -20], [20, 0, -20], [20, 0, 20], [-20, 0, 20]])
    s.add_mesh(ground, np.array([[0, 3, 2, 1]]), material=kauri.Lambert(albedo=(0.3, 0.25, 0.2)), name="ground")
    s.add_group("tree")
    s.add_sphere(center=(0, 1.6, 0), radius=0.8, material=kauri.Lambert(albedo=(0.1, 0.4, 0.08)), group="tree",
                 name="crown")
    trunk = np.array([[-0.1, 0, 0], [0.1, 0, 0], [0.1, 1, 0], [-0.1, 1, 0]])
    s.add_mesh(trunk, np.array([[0, 1, 2, 3]]), material=kauri.Lambert(albedo=(0.25, 0.15, 0.08)), group="tree",
               name="trunk")
    rng = np.random.default_rng(1)
    for i in range(64):
        x, z = rng.uniform(-12, 12, size=2)
        a, k = rng.uniform(0, 2 * math.pi), rng.uniform(0.6, 1.4)
        M = np.array([[k * math.cos(a), 0, k * math.sin(a), x], [0, k, 0, 0],
                      [-k * math.sin(a), 0, k * math.cos(a), z], [0, 0, 0, 1]])
        s.add_instance("tree", M, name=f"tree_{i}")
    s.add_environment(color=(0.5, 0.7, 1.0), intensity=0.6)
    s.add_distant_light(direction=(-1, -1.5, -0.6), angle=0.53, intensity=3.0, temperature=5800, name="sun")
    s.set_camera(eye=(0, 6, 18), target=(0, 0, 0), fov=55)
    return s
