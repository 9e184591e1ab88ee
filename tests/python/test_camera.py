"""Cameras: thin-lens depth of field and the orthographic projection."""
import numpy as np

import kauri


def edge_scene(**camera):
    s = kauri.Scene()
    black = kauri.Lambert(albedo=(0, 0, 0))
    white = kauri.Lambert(albedo=(1, 1, 1))
    s.add_mesh(np.array([[-3, -3, 0], [0, -3, 0], [0, 3, 0], [-3, 3, 0]]), np.array([[0, 1, 2, 3]]), material=black)
    s.add_mesh(np.array([[0, -3, 0], [3, -3, 0], [3, 3, 0], [0, 3, 0]]), np.array([[0, 1, 2, 3]]), material=white)
    s.add_environment(color=(1, 1, 1))
    s.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=20, **camera)
    return s


def transition_width(out):
    row = out.rgba[:, :, 1].mean(axis=0)
    return int(np.sum((row > 0.05) & (row < 0.95)))


def test_thin_lens_focus():
    pinhole = kauri.render(edge_scene(), spp=64, resolution=(64, 16))
    focused = kauri.render(edge_scene(aperture_radius=0.2), spp=64, resolution=(64, 16))
    defocused = kauri.render(edge_scene(aperture_radius=0.2, focus_distance=2.0), spp=64, resolution=(64, 16))
    assert transition_width(pinhole) <= 4
    assert transition_width(focused) <= 4
    # Focused at 2 with the edge at 4: the circle of confusion spans about
    # 2 · 0.2 · (4 − 2)/2 = 0.4 world units ≈ 18 px here.
    assert transition_width(defocused) >= 12


def test_orthographic_width():
    s = kauri.Scene()
    s.add_sphere(radius=1.0, material=kauri.Lambert())
    s.set_camera(kind="orthographic", eye=(0, 0, 5), target=(0, 0, 0), width=4.0)
    out = kauri.render(s, spp=16, resolution=(64, 64))
    # Coverage of a unit disk in a 4 x 4 window: π/16 of the image.
    np.testing.assert_allclose(out.rgba[:, :, 3].mean(), np.pi / 16, rtol=0.02)
    # Orthographic depth is the distance along the view axis: 5 − 1 at the centre.
    np.testing.assert_allclose(out.depth[31:33, 31:33], 4.0, atol=0.01)
