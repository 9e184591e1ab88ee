"""Renders with closed-form answers: a Lambertian plane under each kind of light."""
import numpy as np
import pytest

import kauri

RHO = 0.5


def plane_scene(extent=50.0):
    s = kauri.Scene()
    P = np.array([[-extent, 0, -extent], [extent, 0, -extent], [extent, 0, extent], [-extent, 0, extent]])
    s.add_mesh(P, np.array([[0, 3, 2, 1]]), material=kauri.Lambert(albedo=(RHO, RHO, RHO)), name="plane")
    # Orthographic view straight down onto a 1 x 1 patch at the origin.
    s.set_camera(kind="orthographic", eye=(0, 5, 0), target=(0, 0, 0), up=(0, 0, -1), width=1.0)
    return s


def mean_rgb(out):
    return out.rgba[:, :, :3].reshape(-1, 3).mean(axis=0)


def test_distant_light_irradiance():
    # L = ρ E / π for irradiance E arriving along the normal.
    s = plane_scene()
    s.add_distant_light(direction=(0, -1, 0), intensity=3.0)
    out = kauri.render(s, spp=2048, resolution=(4, 4))
    # The only noise left is spectral (hero wavelengths); 32k samples bring it under 0.5%.
    np.testing.assert_allclose(mean_rgb(out), RHO * 3.0 / np.pi, rtol=0.005)


def test_sun_with_angular_size_matches_its_irradiance():
    # A uniform disc of angular radius θ delivers E = L π sin²θ onto a plane facing it.
    s = plane_scene()
    s.add_distant_light(direction=(0, -1, 0), angle=10.0, intensity=2.0)
    out = kauri.render(s, spp=1024, resolution=(8, 8))
    np.testing.assert_allclose(mean_rgb(out), RHO * 2.0 / np.pi, rtol=0.005)


def test_point_light_inverse_square():
    # Directly below a point light of intensity I at height h: L = ρ/π · I / h².
    s = plane_scene()
    s.set_camera(kind="orthographic", eye=(0, 5, 0), target=(0, 0, 0), up=(0, 0, -1), width=0.02)
    s.add_point_light(position=(0, 2, 0), intensity=8.0)
    out = kauri.render(s, spp=2048, resolution=(4, 4))
    np.testing.assert_allclose(mean_rgb(out), RHO / np.pi * 8.0 / 4.0, rtol=0.005)


def test_spot_light_inside_and_outside_its_cone():
    s = plane_scene()
    s.set_camera(kind="orthographic", eye=(0, 5, 0), target=(0, 0, 0), up=(0, 0, -1), width=0.02)
    s.add_spot_light(position=(0, 2, 0), direction=(0, -1, 0), cone_angle=20, cone_softness=5, intensity=8.0)
    inside = mean_rgb(kauri.render(s, spp=2048, resolution=(4, 4)))
    np.testing.assert_allclose(inside, RHO / np.pi * 8.0 / 4.0, rtol=0.005)
    s2 = plane_scene()
    s2.set_camera(kind="orthographic", eye=(3, 5, 0), target=(3, 0, 0), up=(0, 0, -1), width=0.02)
    s2.add_spot_light(position=(0, 2, 0), direction=(0, -1, 0), cone_angle=20, cone_softness=5, intensity=8.0)
    assert mean_rgb(kauri.render(s2, spp=4, resolution=(8, 8))).max() == 0.0


def test_constant_environment_on_a_plane():
    # The upper hemisphere of radiance c gives irradiance π c: L = ρ c.
    s = plane_scene()
    s.add_environment(color=(1, 1, 1), intensity=2.0)
    out = kauri.render(s, spp=1024, resolution=(8, 8))
    np.testing.assert_allclose(mean_rgb(out), RHO * 2.0, rtol=0.005)


def test_environment_map_importance_sampling_is_unbiased():
    # A sky image: bright band, dim elsewhere, black below the horizon. A plane facing up
    # receives E = ∫ L cosθ dω over the image, integrated here on the texel grid.
    h, w = 64, 128
    v = (np.arange(h) + 0.5) / h
    theta = v * np.pi
    img = np.zeros((h, w, 3), np.float32)
    img[theta < np.pi / 2] = 0.2
    band = (theta > 0.3) & (theta < 0.5)
    img[band, 40:60] = 50.0
    s = plane_scene()
    s.add_environment(image=img)
    out = kauri.render(s, spp=1024, resolution=(8, 8))
    dtheta, dphi = np.pi / h, 2 * np.pi / w
    lum = img[:, :, 0]
    E = (lum * np.cos(theta)[:, None] * np.sin(theta)[:, None]).sum() * dtheta * dphi
    np.testing.assert_allclose(mean_rgb(out), RHO * E / np.pi, rtol=0.02)


def test_area_light_quad_matches_form_factor():
    # A point under the centre of a one-sided square emitter of radiance L at height d
    # receives E = π L F, F the differential-area-to-parallel-rectangle form factor.
    a, d, L = 0.5, 1.0, 4.0
    s = plane_scene()
    # The camera sits between the panel (which faces down) and the plane.
    s.set_camera(kind="orthographic", eye=(0, 0.5, 0), target=(0, 0, 0), up=(0, 0, -1), width=0.01)
    P = np.array([[-a, d, -a], [a, d, -a], [a, d, a], [-a, d, a]])
    s.add_mesh(P, np.array([[0, 1, 2, 3]]), emission=kauri.Emission(intensity=L), name="panel")
    out = kauri.render(s, spp=1024, resolution=(4, 4))
    # Form factor from a point to a parallel rectangle of half-sizes a, a at distance d
    # (four quadrants of the corner formula).
    x = y = a / d
    F_quadrant = (x / np.sqrt(1 + x * x) * np.arctan(y / np.sqrt(1 + x * x))
                  + y / np.sqrt(1 + y * y) * np.arctan(x / np.sqrt(1 + y * y))) / (2 * np.pi)
    E = np.pi * L * 4 * F_quadrant
    np.testing.assert_allclose(mean_rgb(out), RHO * E / np.pi, rtol=0.01)


def _point_probe_scene():
    s = plane_scene()
    s.set_camera(kind="orthographic", eye=(0, 0.2, 0), target=(0, 0, 0), up=(0, 0, -1), width=0.01)
    return s


def test_spherical_emitter_irradiance():
    # A sphere of radiance L, radius r, centre at height d: E = π L (r/d)² on a facing point.
    r, d, L = 0.3, 1.0, 5.0
    s = _point_probe_scene()
    s.add_sphere(center=(0, d, 0), radius=r, emission=kauri.Emission(intensity=L))
    out = kauri.render(s, spp=1024, resolution=(4, 4))
    np.testing.assert_allclose(mean_rgb(out), RHO * L * (r / d) ** 2, rtol=0.01)


def test_disk_emitter_irradiance_two_sided():
    # On the axis of a disk of radius r at distance d: E = π L r² / (r² + d²).
    r, d, L = 0.5, 1.0, 3.0
    s = _point_probe_scene()
    s.add_disk(center=(0, d, 0), normal=(0, 1, 0), radius=r,
               emission=kauri.Emission(intensity=L, two_sided=True))
    out = kauri.render(s, spp=1024, resolution=(4, 4))
    np.testing.assert_allclose(mean_rgb(out), RHO * L * r * r / (r * r + d * d), rtol=0.01)
    # One-sided and facing away: no light.
    s = _point_probe_scene()
    s.add_disk(center=(0, d, 0), normal=(0, 1, 0), radius=r, emission=kauri.Emission(intensity=L))
    assert mean_rgb(kauri.render(s, spp=16, resolution=(4, 4))).max() == 0.0


def test_blackbody_emitter_has_its_luminance_and_warm_colour():
    # A 3000 K emitter normalised to luminance 1 lights a white plane warmer than a 9000 K one.
    def render(T):
        s = _point_probe_scene()
        s.add_disk(center=(0, 1, 0), normal=(0, -1, 0), radius=0.5, emission=kauri.Emission(temperature=T))
        return mean_rgb(kauri.render(s, spp=1024, resolution=(4, 4)))
    warm, cold = render(3000.0), render(9000.0)
    assert warm[0] / warm[2] > 1.5 > cold[0] / cold[2]
    ap1_y = np.array([0.2722287, 0.6740818, 0.0536895])
    expected_y = RHO * 0.25 / (0.25 + 1.0)  # luminance-normalised: E_Y = π · 1 · r²/(r²+d²)
    np.testing.assert_allclose(warm @ ap1_y, expected_y, rtol=0.02)
    np.testing.assert_allclose(cold @ ap1_y, expected_y, rtol=0.02)


@pytest.mark.parametrize("y0,z1,z2,a", [(0.5, 1.46, 1.70, 0.12), (0.2, 1.0, 1.24, 0.12), (1.0, 0.1, 0.5, 0.3)])
def test_one_sided_quad_light_at_grazing_angles(y0, z1, z2, a):
    # A wall (z = 0, facing +z) lit by a small down-facing quad lamp in front of and above
    # it, as in the hangar scene's upper back wall: emission and incidence are both grazing.
    # E = ∫ L cosθ_r cosθ_l / r² dA over the lamp (midpoint rule, 2000² cells).
    rho, L = 0.5, 4.0
    s = kauri.Scene()
    P = np.array([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]])
    s.add_mesh(P, np.array([[0, 1, 2, 3]]), material=kauri.Lambert(albedo=(rho,) * 3), name="wall")
    Q = np.array([[-a, y0, z1], [a, y0, z1], [a, y0, z2], [-a, y0, z2]])
    s.add_mesh(Q, np.array([[0, 1, 2, 3]]), emission=kauri.Emission(intensity=L), name="lamp")
    s.set_camera(kind="orthographic", eye=(0, 0, 0.5), target=(0, 0, 0), up=(0, 1, 0), width=0.002)
    out = kauri.render(s, spp=4096, resolution=(4, 4), max_depth=1)
    n = 2000
    x = (np.arange(n) + 0.5) / n * 2 * a - a
    z = (np.arange(n) + 0.5) / n * (z2 - z1) + z1
    X, Z = np.meshgrid(x, z)
    r2 = X ** 2 + y0 ** 2 + Z ** 2
    E = (L * (Z / np.sqrt(r2)) * (y0 / np.sqrt(r2)) / r2).sum() * (2 * a / n) * ((z2 - z1) / n)
    np.testing.assert_allclose(mean_rgb(out), rho * E / np.pi, rtol=0.005)


def test_lights_seen_directly_add_their_colour_without_colour_noise():
    # A camera ray that meets a light adds the expected colour of the light's spectrum over
    # the path wavelengths (trace_path: add_area_seen_directly), not a 4-wavelength estimate
    # of it: a panel that fills the view, and a constant environment, render one value at
    # every pixel and for every seed, which is their RGB up to the spectral uplift's round trip.
    def panel(seed):
        s = kauri.Scene()
        P = np.array([[-50, 0, -50], [50, 0, -50], [50, 0, 50], [-50, 0, 50]])
        s.add_mesh(P, np.array([[0, 3, 2, 1]]), name="panel",
                   emission=kauri.Emission(color=(0.9, 0.3, 0.05), intensity=2.0, two_sided=True))
        s.set_camera(kind="orthographic", eye=(0, 5, 0), target=(0, 0, 0), up=(0, 0, -1), width=1.0)
        return kauri.render(s, spp=4, resolution=(8, 8), seed=seed).rgba[:, :, :3]

    def sky(seed):
        s = kauri.Scene()
        # A point light of the same spectrum first (never seen, so its colour is not
        # integrated; the sky, which shares its emission id, must still get its own).
        s.add_point_light(position=(0, -3, 0), color=(0.2, 0.5, 1.0), intensity=1.5)
        s.add_environment(color=(0.2, 0.5, 1.0), intensity=1.5)
        s.set_camera(kind="orthographic", eye=(0, 5, 0), target=(0, 6, 0), up=(0, 0, -1), width=1.0)
        return kauri.render(s, spp=4, resolution=(8, 8), seed=seed).rgba[:, :, :3]

    for render, rgb in ((panel, np.array([1.8, 0.6, 0.1])), (sky, np.array([0.3, 0.75, 1.5]))):
        a, b = render(1), render(2)
        np.testing.assert_allclose(a, np.broadcast_to(a[0, 0], a.shape), rtol=1e-5)
        np.testing.assert_allclose(b, a, rtol=1e-5)
        np.testing.assert_allclose(a[0, 0], rgb, rtol=0.02)
