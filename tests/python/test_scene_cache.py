"""kauri.render keeps a scene's compiled form (BVH, lights) and reuses it while the scene is
unchanged: a later render at the same size skips the compile, and any change (new shape,
light, material, camera) or another image size compiles again. The images must be exactly
those of a freshly built scene either way."""
import numpy as np

import kauri


def build(extra_light=False, eye=(0, 1, 4)):
    s = kauri.Scene(color_space="srgb")
    s.add_mesh(np.array([(-2, 0, 2), (2, 0, 2), (2, 0, -2), (-2, 0, -2)], np.float32), np.array([[0, 1, 2, 3]]),
               material=kauri.Lambert(albedo=(0.6, 0.5, 0.4), name="floor"), name="floor")
    s.add_sphere(center=(0, 0.5, 0), radius=0.5, material=kauri.Lambert(albedo=(0.3, 0.6, 0.8), name="ball"),
                 name="ball")
    s.add_point_light(position=(1, 3, 1), intensity=20)
    if extra_light:
        s.add_point_light(position=(-2, 2, 1), color=(1, 0.5, 0.2), intensity=10, name="fill")
    s.set_camera(eye=eye, target=(0, 0.4, 0), fov=45)
    return s


def render(s, res=(24, 16)):
    return kauri.render(s, spp=4, resolution=res, seed=3, progress=False, aovs=False)


def test_unchanged_scene_reuses_its_compiled_form():
    s = build()
    first, second = render(s), render(s)
    assert not first.stats["scene_reused"] and first.stats["compile_seconds"] > 0
    assert second.stats["scene_reused"] and second.stats["compile_seconds"] == 0
    assert "compiled scene reused" in second.stats["summary"]
    np.testing.assert_array_equal(first.rgba, second.rgba)


def test_any_change_compiles_again_and_renders_the_change():
    s = build()
    render(s)
    s.add_point_light(position=(-2, 2, 1), color=(1, 0.5, 0.2), intensity=10, name="fill")
    changed = render(s)
    assert not changed.stats["scene_reused"]
    np.testing.assert_array_equal(changed.rgba, render(build(extra_light=True)).rgba)
    s.set_camera(eye=(1, 2, 4), target=(0, 0.4, 0), fov=45)
    moved = render(s)
    assert not moved.stats["scene_reused"]
    np.testing.assert_array_equal(moved.rgba, render(build(extra_light=True, eye=(1, 2, 4))).rgba)
    assert render(s).stats["scene_reused"]


def test_another_image_size_compiles_again():
    s = build()
    render(s)
    other = render(s, res=(16, 24))
    assert not other.stats["scene_reused"]
    np.testing.assert_array_equal(other.rgba, render(build(), res=(16, 24)).rgba)
