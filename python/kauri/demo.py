"""The built-in demo scene: a Cornell-box-like room with a diffuse area light,
a glass sphere (with dispersion) and a rough gold sphere, built through the public API."""
from __future__ import annotations

import numpy as np

from .scene import Conductor, Dielectric, Emission, Lambert, Scene


def _quad(a, b, c, d):
    return np.array([a, b, c, d], dtype=np.float32), np.array([[0, 1, 2, 3]], dtype=np.uint32)


def build(color_space: str = "acescg") -> Scene:
    s = Scene(color_space=color_space)
    white = Lambert(albedo=(0.73, 0.73, 0.73), name="white")
    red = Lambert(albedo=(0.63, 0.065, 0.05), name="red")
    green = Lambert(albedo=(0.14, 0.45, 0.091), name="green")
    # Room: x ∈ [-1, 1], y ∈ [0, 2], z ∈ [-1, 1]; open towards +z. Quads wind so the
    # normals face into the room.
    walls = {
        "floor": (_quad((-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)), white),
        "ceiling": (_quad((-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)), white),
        "back": (_quad((-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)), white),
        "left": (_quad((-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)), red),
        "right": (_quad((1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)), green),
    }
    for name, ((P, I), mat) in walls.items():
        s.add_mesh(P, I, material=mat, name=name)
    P, I = _quad((-0.3, 1.995, -0.3), (0.3, 1.995, -0.3), (0.3, 1.995, 0.3), (-0.3, 1.995, 0.3))  # faces down
    s.add_mesh(P, I, emission=Emission(color=(1.0, 0.85, 0.65), intensity=17.0), name="light",
               material=Lambert(albedo=(0.78, 0.78, 0.78), name="light_diffuser"))
    s.add_sphere(center=(-0.42, 0.38, -0.25), radius=0.38,
                 material=Conductor(metal="Au", roughness=0.35, name="rough_gold"), name="gold_sphere")
    s.add_sphere(center=(0.42, 0.38, 0.3), radius=0.38,
                 material=Dielectric(ior=1.5, abbe=40.0, name="glass"), name="glass_sphere")
    s.set_camera(eye=(0, 1, 3.85), target=(0, 1, 0), fov=38, fov_axis="y")
    return s
