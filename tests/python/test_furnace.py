"""White-furnace renders: a convex object in a uniform environment of radiance 1."""
import numpy as np
import pytest

import kauri
from conftest import interior_mean


@pytest.mark.parametrize("rho", [0.2, 0.8, 1.0])
@pytest.mark.parametrize("color_space", ["acescg", "srgb"])
def test_lambert_sphere_renders_its_albedo(furnace_scene, rho, color_space):
    # A convex Lambertian surface under uniform radiance 1 reflects exactly ρ.
    s = furnace_scene(kauri.Lambert(albedo=(rho, rho, rho)), color_space)
    out = kauri.render(s, spp=64, resolution=(64, 64), seed=1)
    mean = interior_mean(out)
    np.testing.assert_allclose(mean, rho, rtol=0.005)


def test_smooth_dielectric_sphere_is_invisible_in_the_furnace(furnace_scene):
    # A non-absorbing dielectric neither creates nor destroys energy: it renders 1.
    s = furnace_scene(kauri.Dielectric(ior=1.5))
    out = kauri.render(s, spp=128, resolution=(64, 64), seed=2, max_depth=128, max_transmission=128,
                       max_glossy=128)
    mean = interior_mean(out)
    np.testing.assert_allclose(mean, 1.0, rtol=0.005)


def test_dispersive_dielectric_keeps_energy(furnace_scene):
    # Dispersion terminates secondary wavelengths; the hero must then carry all four.
    s = furnace_scene(kauri.Dielectric(ior=1.5, abbe=20))
    out = kauri.render(s, spp=256, resolution=(48, 48), seed=3, max_depth=128, max_transmission=128,
                       max_glossy=128)
    np.testing.assert_allclose(interior_mean(out), 1.0, rtol=0.01)


def test_smooth_white_conductor_reflects_everything(furnace_scene):
    # F = 1 (κ → ∞) on a mirror sphere: radiance 1 everywhere.
    s = furnace_scene(kauri.Conductor(eta=(1, 1, 1), k=(1e4, 1e4, 1e4), roughness=0.0))
    out = kauri.render(s, spp=16, resolution=(48, 48), seed=4)
    np.testing.assert_allclose(interior_mean(out), 1.0, rtol=0.005)


def _ggx_single_scatter_albedo(alpha, mu, n=300):
    """E(μ) = ∫ D G / (4 μ μ_i) μ_i dω_i for F = 1 (Smith height-correlated G), by quadrature."""
    wo = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    th = (np.arange(n) + 0.5) / n * np.pi / 2
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
    T, P = np.meshgrid(th, ph, indexing="ij")
    wi = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    c2 = h[..., 2] ** 2
    D = 1 / (np.pi * alpha**2 * c2**2 * (1 + (1 - c2) / c2 / alpha**2) ** 2)
    lam = lambda c: (np.sqrt(1 + alpha**2 * (1 - c * c) / (c * c)) - 1) / 2
    f = D / (1 + lam(mu) + lam(wi[..., 2])) / (4 * mu * wi[..., 2])
    return float((f * wi[..., 2] * np.sin(T)).sum() * (np.pi / 2 / n) * (np.pi / n))


@pytest.mark.parametrize("roughness", [0.3, 0.6, 1.0])
def test_compensated_rough_white_conductor_keeps_its_energy(furnace_scene, roughness):
    # Kulla–Conty compensation (ggx_conductor@2) restores the multiply scattered energy.
    s = furnace_scene(kauri.Conductor(eta=(1, 1, 1), k=(1e4, 1e4, 1e4), roughness=roughness))
    out = kauri.render(s, spp=64, resolution=(48, 48), seed=6)
    np.testing.assert_allclose(interior_mean(out), 1.0, rtol=0.01)


@pytest.mark.parametrize("ior,roughness", [(1.33, 0.3), (1.5, 0.6), (1.5, 1.0)])
def test_compensated_rough_dielectric_sphere_keeps_its_energy(furnace_scene, ior, roughness):
    # ggx_dielectric@2: Kulla–Conty-style compensation for both reflection and transmission.
    s = furnace_scene(kauri.RoughDielectric(ior=ior, roughness=roughness))
    out = kauri.render(s, spp=64, resolution=(48, 48), seed=7, max_depth=128, max_transmission=128,
                       max_glossy=128)
    np.testing.assert_allclose(interior_mean(out), 1.0, rtol=0.015)


def test_rough_white_conductor_matches_single_scattering_albedo(furnace_scene):
    # Without multiple-scattering compensation (ggx_conductor@1) a rough F = 1 conductor
    # reflects its single-scattering albedo E(μ). Over a sphere seen from afar, μ = cosθ
    # has density 2μ across the image, so the mean is ∫ E(μ) 2μ dμ.
    roughness = 0.5
    s = furnace_scene(kauri.Conductor(eta=(1, 1, 1), k=(1e4, 1e4, 1e4), roughness=roughness, compensate=False))
    out = kauri.render(s, spp=64, resolution=(48, 48), seed=5)
    mus = np.linspace(0.02, 1, 40)
    E = np.array([_ggx_single_scatter_albedo(roughness**2, m) for m in mus])
    expected = np.trapezoid(E * 2 * mus, mus)
    mean = interior_mean(out)
    assert np.all(mean <= 1.0)
    # The camera is at a finite distance, so μ is not exactly 2μ-distributed: 1.5%.
    np.testing.assert_allclose(mean, expected, rtol=0.015)


@pytest.mark.parametrize("roughness", [0.0, 0.5, 1.0])
def test_oren_nayar_white_furnace(furnace_scene, roughness):
    s = furnace_scene(kauri.OrenNayar(albedo=(1, 1, 1), roughness=roughness))
    out = kauri.render(s, spp=64, resolution=(48, 48), seed=8)
    np.testing.assert_allclose(interior_mean(out), 1.0, rtol=0.005)
