import numpy as np
import pytest

import kauri


@pytest.fixture
def furnace_scene():
    """A sphere inside a uniform environment of radiance 1 (white in the working space)."""
    def make(material, color_space="acescg"):
        s = kauri.Scene(color_space=color_space)
        s.add_sphere(center=(0, 0, 0), radius=1.0, material=material, name="ball")
        s.add_environment(color=(1, 1, 1))
        s.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=35)
        return s
    return make


def interior_mean(out):
    """Mean RGB over pixels whose every sample hit the sphere (alpha == 1)."""
    mask = out.rgba[:, :, 3] >= 1.0
    assert mask.sum() > 100, "the sphere should cover many pixels"
    return out.rgba[:, :, :3][mask].mean(axis=0)
