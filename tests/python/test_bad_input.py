"""Bad input raises a clear exception naming the object and the parameter, never a crash."""
import numpy as np
import pytest

import kauri

QUAD_P = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], np.float32)
QUAD_I = np.array([[0, 1, 2, 3]])


def scene():
    s = kauri.Scene()
    s.set_camera(eye=(0, 1, 5), target=(0, 0, 0))
    return s


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_vertex(bad):
    P = QUAD_P.copy()
    P[2, 1] = bad
    with pytest.raises(ValueError, match=r"mesh 'floor'.*positions.*vertex 2.*not finite"):
        scene().add_mesh(P, QUAD_I, name="floor")


def test_out_of_range_index():
    with pytest.raises(ValueError, match=r"mesh 'floor'.*indices.*index 7 is out of range.*4 vertices"):
        scene().add_mesh(QUAD_P, np.array([[0, 1, 7]]), name="floor")
    with pytest.raises(ValueError, match=r"mesh 'floor'.*indices.*-1"):
        scene().add_mesh(QUAD_P, np.array([[0, 1, -1]]), name="floor")


def test_wrong_shapes_and_types():
    with pytest.raises(ValueError, match=r"mesh 'm'.*positions.*\(n, 3\)"):
        scene().add_mesh(np.zeros((4, 2)), QUAD_I, name="m")
    with pytest.raises(ValueError, match=r"mesh 'm'.*indices.*\(m, 3\) or \(m, 4\)"):
        scene().add_mesh(QUAD_P, np.array([[0, 1, 2, 3, 0]]), name="m")
    with pytest.raises(ValueError, match=r"mesh 'm'.*indices.*integers"):
        scene().add_mesh(QUAD_P, np.array([[0.0, 1.0, 2.0]]), name="m")
    with pytest.raises(ValueError, match=r"mesh 'm'.*normals"):
        scene().add_mesh(QUAD_P, QUAD_I, normals=np.zeros((3, 3)), name="m")
    with pytest.raises(ValueError, match=r"mesh 'm'.*material.*Lambert"):
        scene().add_mesh(QUAD_P, QUAD_I, material="red", name="m")


@pytest.mark.parametrize("radius", [-1.0, 0.0, np.nan])
def test_bad_sphere_radius(radius):
    with pytest.raises(ValueError, match=r"sphere 'ball'.*radius"):
        scene().add_sphere(center=(0, 0, 0), radius=radius, name="ball")


def test_bad_disk():
    with pytest.raises(ValueError, match=r"disk 'd'.*radius"):
        scene().add_disk(radius=-2, name="d")
    with pytest.raises(ValueError, match=r"disk 'd'.*normal.*non-zero"):
        scene().add_disk(normal=(0, 0, 0), name="d")


def test_zero_area_emitter():
    P = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], np.float32)  # collinear
    with pytest.raises(ValueError, match=r"mesh 'lamp'.*emission.*non-zero area"):
        scene().add_mesh(P, np.array([[0, 1, 2]]), emission=kauri.Emission(intensity=5), name="lamp")


def test_negative_emission():
    with pytest.raises(ValueError, match=r"sphere 's'.*emission.color"):
        scene().add_sphere(radius=1, emission=kauri.Emission(color=(1, -1, 1)), name="s")
    with pytest.raises(ValueError, match=r"light 'key'.*intensity"):
        scene().add_point_light(position=(0, 1, 0), intensity=-3, name="key")


def test_unknown_parameters_are_named():
    with pytest.raises(ValueError, match=r"material 'lambert'.*unknown parameter.*'colour'"):
        kauri.Lambert(colour=(1, 0, 0))
    with pytest.raises(ValueError, match=r"material 'glass'.*unknown parameter.*'eta'"):
        kauri.Dielectric(eta=1.5, name="glass")
    with pytest.raises(ValueError, match=r"sphere 'ball'.*unknown parameter.*'raduis'"):
        scene().add_sphere(raduis=2, name="ball")
    with pytest.raises(ValueError, match=r"light 'sun'.*unknown parameter.*'power'"):
        scene().add_distant_light(direction=(0, -1, 0), power=3, name="sun")
    with pytest.raises(ValueError, match=r"camera.*unknown parameter.*'fov_y'"):
        scene().set_camera(fov_y=30)
    with pytest.raises(ValueError, match=r"render.*unknown parameter.*'samples'"):
        kauri.render(scene(), samples=4)


def test_out_of_range_material_parameters():
    with pytest.raises(ValueError, match=r"material 'paint'.*albedo.*\[0, 1\]"):
        kauri.Lambert(albedo=(1.2, 0.5, 0.5), name="paint")
    with pytest.raises(ValueError, match=r"material 'metal'.*roughness"):
        kauri.Conductor(roughness=2.0, name="metal")
    with pytest.raises(ValueError, match=r"material 'conductor'.*metal.*unknown metal 'Unobtainium'.*Au"):
        scene().add_sphere(material=kauri.Conductor(metal="Unobtainium"))
    with pytest.raises(ValueError, match=r"material 'glass'.*ior"):
        kauri.Dielectric(ior=float("nan"), name="glass")
    with pytest.raises(ValueError, match=r"material 'glass'.*ior.*number"):
        kauri.Dielectric(ior="1.5", name="glass")


def test_bad_camera_and_render_settings():
    s = kauri.Scene()
    with pytest.raises(ValueError, match=r"camera.*target.*differ"):
        s.set_camera(eye=(0, 0, 0), target=(0, 0, 0))
    with pytest.raises(ValueError, match=r"camera.*up.*parallel"):
        s.set_camera(eye=(0, 0, 0), target=(0, 1, 0), up=(0, 1, 0))
    with pytest.raises(ValueError, match=r"render.*no camera"):
        kauri.render(kauri.Scene())
    with pytest.raises(ValueError, match=r"render.*spp"):
        kauri.render(scene(), spp=0)
    with pytest.raises(ValueError, match=r"render.*resolution"):
        kauri.render(scene(), resolution=(0, 10))
    with pytest.raises(ValueError, match=r"render.*sampler"):
        kauri.render(scene(), sampler="halton")


def test_bad_instances_and_environment():
    s = scene()
    s.add_group("tree")
    with pytest.raises(ValueError, match=r"instance 'i'.*transform.*singular"):
        s.add_instance("tree", np.zeros((4, 4)), name="i")
    with pytest.raises(ValueError, match=r"instance 'i'.*group.*unknown group 'bush'"):
        s.add_instance("bush", np.eye(4), name="i")
    img = np.ones((8, 16, 3), np.float32)
    img[2, 3, 1] = np.nan
    with pytest.raises(ValueError, match=r"light 'sky'.*image.*finite"):
        s.add_environment(image=img, name="sky")
    with pytest.raises(ValueError, match=r"cannot open image"):
        s.add_environment(image="/nonexistent/sky.exr")


def test_errors_leave_the_scene_usable():
    s = scene()
    with pytest.raises(ValueError):
        s.add_sphere(radius=-1)
    s.add_sphere(radius=1, material=kauri.Lambert())
    s.add_environment()
    out = kauri.render(s, spp=1, resolution=(8, 8))
    assert np.all(np.isfinite(out.rgba))
