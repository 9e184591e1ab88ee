"""Two-level instancing: transformed prototypes shade and emit like their flat copies."""
import numpy as np

import kauri
from conftest import interior_mean


def test_instanced_scaled_sphere_in_furnace():
    s = kauri.Scene()
    s.add_group("ball")
    s.add_sphere(center=(0.5, 0, 0), radius=0.5, material=kauri.Lambert(albedo=(0.6, 0.6, 0.6)), group="ball")
    # Non-uniform placement: scale 2, rotate about y, translate: a sphere of radius 1 at the origin.
    c, si = np.cos(0.7), np.sin(0.7)
    M = np.array([[2 * c, 0, 2 * si, 0], [0, 2, 0, 0], [-2 * si, 0, 2 * c, 0], [0, 0, 0, 1]], float)
    M[:3, 3] = -(M[:3, :3] @ np.array([0.5, 0, 0]))
    s.add_instance("ball", M)
    s.add_environment(color=(1, 1, 1))
    s.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=35)
    out = kauri.render(s, spp=64, resolution=(48, 48), seed=2)
    np.testing.assert_allclose(interior_mean(out), 0.6, rtol=0.005)
    # The silhouette matches a radius-1 sphere: compare coverage with a flat copy.
    flat = kauri.Scene()
    flat.add_sphere(radius=1.0, material=kauri.Lambert(albedo=(0.6, 0.6, 0.6)))
    flat.add_environment(color=(1, 1, 1))
    flat.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=35)
    ref = kauri.render(flat, spp=64, resolution=(48, 48), seed=2)
    assert abs(out.rgba[:, :, 3].sum() - ref.rgba[:, :, 3].sum()) < 3


def _lamp_scene(instanced):
    s = kauri.Scene()
    P = np.array([[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]])
    s.add_mesh(P, np.array([[0, 3, 2, 1]]), material=kauri.Lambert(albedo=(0.5, 0.5, 0.5)))
    lamp = np.array([[-0.2, 0, -0.2], [0.2, 0, -0.2], [0.2, 0, 0.2], [-0.2, 0, 0.2]])
    em = kauri.Emission(intensity=10)
    if instanced:
        s.add_group("lamp")
        s.add_mesh(lamp, np.array([[0, 1, 2, 3]]), emission=em, group="lamp")
        for x in (-1.0, 1.0):
            s.add_instance("lamp", np.array([[1, 0, 0, x], [0, 1, 0, 1.0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    else:
        for x in (-1.0, 1.0):
            s.add_mesh(lamp + np.array([x, 1.0, 0]), np.array([[0, 1, 2, 3]]), emission=em)
    s.set_camera(kind="orthographic", eye=(0, 0.5, 0.0), target=(0, 0, 0), up=(0, 0, -1), width=3.0)
    return s


def test_instanced_emitters_light_like_flat_ones():
    a = kauri.render(_lamp_scene(True), spp=256, resolution=(16, 16), seed=1)
    b = kauri.render(_lamp_scene(False), spp=256, resolution=(16, 16), seed=1)
    assert a.stats["nan_samples"] == 0
    ma, mb = a.rgba[:, :, :3].mean(), b.rgba[:, :, :3].mean()
    assert mb > 0.01
    np.testing.assert_allclose(ma, mb, rtol=0.01)
