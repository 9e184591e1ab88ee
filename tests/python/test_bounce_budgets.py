"""Per-type bounce budgets end a path MIS-correctly: the scattering event that exceeds a
budget still traces its ray for the emission it finds (the BSDF half of that vertex's direct
light), then the path stops. So `max_diffuse=0` is direct lighting on diffuse surfaces, no
darker; on an all-diffuse scene it is exactly `max_depth=1`, and likewise for the glossy and
transmission budgets on scenes of one kind."""
import numpy as np
import pytest

import kauri

from conftest import interior_mean


def render(s, **kw):
    return kauri.render(s, spp=16, resolution=(32, 32), seed=5, progress=False, aovs=False, **kw)


def diffuse_room():
    s = kauri.Scene(color_space="srgb")
    quad = np.array([[0, 1, 2, 3]])
    for name, pts, col in (("floor", [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)], (0.7, 0.7, 0.7)),
                           ("back", [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)], (0.6, 0.5, 0.4)),
                           ("left", [(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)], (0.7, 0.2, 0.2))):
        s.add_mesh(np.array(pts, np.float32), quad, material=kauri.Lambert(albedo=col, name=name), name=name)
    s.add_mesh(np.array([(-0.3, 1.99, -0.3), (0.3, 1.99, -0.3), (0.3, 1.99, 0.3), (-0.3, 1.99, 0.3)], np.float32),
               quad, emission=kauri.Emission(color=(1, 1, 1), intensity=10), name="lamp")
    s.add_environment(color=(0.3, 0.35, 0.4))
    s.set_camera(eye=(0, 1, 3.5), target=(0, 0.8, 0), fov=50)
    return s


def test_diffuse_budget_zero_is_direct_lighting():
    s = diffuse_room()
    direct = render(s, max_depth=1)
    np.testing.assert_array_equal(render(s, max_diffuse=0).rgba, direct.rgba)
    # ... and more diffuse bounces add light.
    assert render(s, max_diffuse=2).rgba[..., :3].mean() > 1.05 * direct.rgba[..., :3].mean()


def test_glossy_budget_zero_is_direct_lighting():
    s = kauri.Scene(color_space="srgb")
    s.add_sphere(center=(0, 0, 0), radius=1, material=kauri.Conductor(metal="Au", roughness=0.4, name="gold"),
                 name="ball")
    s.add_sphere(center=(1.6, 0, -0.5), radius=0.6, material=kauri.Conductor(metal="Cu", roughness=0.5, name="cu"),
                 name="ball2")
    s.add_environment(color=(0.8, 0.9, 1.0))
    s.add_point_light(position=(2, 3, 2), intensity=30)
    s.set_camera(eye=(0, 0.5, 4), target=(0.3, 0, 0), fov=50)
    np.testing.assert_array_equal(render(s, max_glossy=0).rgba, render(s, max_depth=1).rgba)


def test_diffuse_budget_zero_keeps_the_furnace_albedo(furnace_scene):
    # A convex Lambertian sphere in a uniform environment shows ρ · L = ρ whatever the
    # budget: all of its light is direct (environment light is found by BSDF sampling alone).
    for budget in (0, 1, 6):
        out = kauri.render(furnace_scene(kauri.Lambert(albedo=(0.5, 0.5, 0.5), name="m")), spp=64,
                           resolution=(32, 32), max_diffuse=budget, progress=False, aovs=False)
        np.testing.assert_allclose(interior_mean(out), 0.5, rtol=0.01)


# The six faces of the cube [-1, 1]^3, as quads.
CUBE_QUADS = [[(-1, -1, 1), (1, -1, 1), (1, -1, -1), (-1, -1, -1)], [(-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1)],
              [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1)], [(1, -1, 1), (-1, -1, 1), (-1, 1, 1), (1, 1, 1)],
              [(-1, -1, 1), (-1, -1, -1), (-1, 1, -1), (-1, 1, 1)], [(1, -1, -1), (1, -1, 1), (1, 1, 1), (1, 1, -1)]]


def mirror_box(roughness):
    """A closed cube of aluminium, the camera inside: no ray ever leaves, no surface is diffuse."""
    s = kauri.Scene(color_space="srgb")
    metal = kauri.Conductor(metal="Al", roughness=roughness)
    for k, q in enumerate(CUBE_QUADS):
        s.add_mesh(np.array(q, np.float32), np.array([[0, 1, 2, 3]]), material=metal, name=f"wall{k}")
    s.add_point_light(position=(0.3, 0.5, 0.2), intensity=1)
    s.set_camera(eye=(0, 0, 0.5), target=(0, 0, -1), fov=60)
    return s


@pytest.mark.parametrize("roughness", [0.0, 0.2])
def test_russian_roulette_waits_for_diffuse_bounces(roughness):
    # Russian roulette starts after rr_min_depth (4) diffuse bounces: a path between metal
    # walls (throughput ~0.9 per bounce) is never cut short, every camera sample makes
    # max_depth + 1 closest-hit queries, plus one shadow ray per rough (non-delta) vertex.
    # Counting every bounce, roulette would end some of them after bounce 4.
    depth = 12
    out = kauri.render(mirror_box(roughness), spp=4, resolution=(8, 8), seed=1, progress=False, aovs=False,
                       max_depth=depth, max_glossy=64)
    closest = out.stats["samples"] * (depth + 1)
    if roughness == 0:
        assert out.stats["rays"] == closest
    else:
        # Shadow rays are traced where the light faces the vertex with a nonzero BSDF: at
        # most one per vertex below max_depth, and most of them in a closed box.
        assert closest + 0.5 * out.stats["samples"] * depth <= out.stats["rays"] <= closest + out.stats["samples"] * depth


def emissive_box(rho):
    s = kauri.Scene(color_space="acescg")
    wall = kauri.Lambert(albedo=(rho, rho, rho))
    for k, q in enumerate(CUBE_QUADS):
        s.add_mesh(np.array(q, np.float32), np.array([[0, 1, 2, 3]]), material=wall,
                   emission=kauri.Emission(two_sided=True), name=f"wall{k}")
    s.set_camera(eye=(0, 0, 0.5), target=(0, 0, -1), fov=60)
    return s


def test_russian_roulette_is_unbiased_in_an_emissive_box():
    # The camera inside a closed cube whose walls are grey Lambert (rho = 0.8) and emit
    # Le = 1 (two-sided, white): every point sees only the walls, so the radiance is
    # L = Le (1 + rho + rho^2 + ...) = Le / (1 - rho) = 5 everywhere. A third of it comes
    # from paths longer than 4 diffuse bounces, where Russian roulette decides: a survival
    # probability not undone by its weight would show here. Bounce budgets of 64 leave
    # rho^65 ~ 5e-7 of the series out.
    rho = 0.8
    out = kauri.render(emissive_box(rho), spp=64, resolution=(16, 16), seed=3, progress=False, aovs=False,
                       max_depth=64, max_diffuse=64)
    # One render's mean over its pixels scatters by ~0.3% (six seeds); a roulette that
    # dropped its 1/p weight would lose a sizeable part of the third past bounce 4.
    mean = out.rgba[:, :, :3].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(mean, 1 / (1 - rho), rtol=0.01)
    # And the paths really are long: well over the 4 bounces before roulette, on average.
    assert out.stats["rays"] / out.stats["samples"] > 2 * 4


def test_rr_depth_trades_rays_for_noise_not_brightness():
    # rr_depth moves where roulette starts: from the first diffuse bounce (0), the default
    # 4, or never (above the diffuse budget: every path in the closed box then makes all 64
    # bounces, 65 closest-hit queries per camera sample). The image mean stays
    # Le / (1 - rho) = 5 whichever, and earlier roulette traces fewer rays.
    rho, depth = 0.8, 64
    s = emissive_box(rho)
    rays = {}
    for rr in (0, 4, depth + 1):
        out = kauri.render(s, spp=32, resolution=(16, 16), seed=7, progress=False, aovs=False,
                           max_depth=depth, max_diffuse=depth, rr_depth=rr)
        mean = out.rgba[:, :, :3].reshape(-1, 3).mean(axis=0)
        np.testing.assert_allclose(mean, 1 / (1 - rho), rtol=0.015)
        rays[rr] = out.stats["rays"] / out.stats["samples"]
    assert rays[0] < 0.95 * rays[4]  # 12.0 against 13.7 here: survival ~0.8^(1/3) per bounce
    # No roulette: every camera sample makes 65 closest-hit queries and at most 64 shadow rays.
    assert depth + 1 <= rays[depth + 1] <= 2 * depth + 1
    assert rays[4] < 0.5 * rays[depth + 1]


@pytest.mark.parametrize("bad", [-1, 1.5, True, "4"])
def test_rr_depth_must_be_a_count(bad):
    with pytest.raises(kauri.SceneError, match="rr_depth"):
        kauri.render(emissive_box(0.5), spp=1, resolution=(4, 4), progress=False, rr_depth=bad)
