"""Material palette: six layered materials from the course notes' workflows, on spheres
in a 3 × 2 grid (a contact sheet in one render).

Top row, left to right: car paint (clear coat over a metallic-flake base), wet concrete
(water film with IOR and roughness accumulation), the leaf stack of §8.5.1.
Bottom row: brushed anisotropic aluminium, thin glass, fabric with sheen.

    kauri render scenes/material_palette.py -o palette.exr --res 900x600 --spp 256
"""
import numpy as np

import kauri


def car_paint():
    m = kauri.Material("car_paint")
    m.add_lobe("pigment", kauri.Lambert(albedo=(0.45, 0.02, 0.03)))
    m.add_lobe("flakes", kauri.Conductor(reflectivity=(0.9, 0.3, 0.25), edge_tint=(1.0, 0.6, 0.5), roughness=0.4),
               weight=0.3)
    m.combine("base", "blend", "flakes", "pigment")
    m.add_lobe("clear", kauri.Dielectric(ior=1.5))
    m.combine("paint", "coat", "clear", "base")
    return m


def wet_concrete(wetness=0.8):
    m = kauri.Material("wet_concrete", ior_accumulation=True, roughness_accumulation=True)
    m.add_lobe("water", kauri.RoughDielectric(ior=1.33, roughness=0.08), weight=wetness)
    m.add_lobe("grit", kauri.Lambert(albedo=(0.38, 0.37, 0.35)))
    # The concrete's own dull sheen: a dielectric-like reflector (κ = 0) of IOR 1.5.
    m.add_lobe("sheen", kauri.Conductor(eta=(1.5, 1.5, 1.5), k=(0, 0, 0), roughness=0.7), weight=0.3)
    m.combine("concrete", "coat", "sheen", "grit")
    m.combine("wet", "coat", "water", "concrete")
    return m


def leaf():
    """§8.5.1: two opaque diffuse layers (front colour over back colour), mixed with a
    tinted diffuse transmission, glossy coats on top and beneath, single-sided, with IOR
    and roughness accumulation."""
    m = kauri.Material("leaf", symmetric=False, ior_accumulation=True, roughness_accumulation=True)
    m.add_lobe("front", kauri.Lambert(albedo=(0.08, 0.3, 0.04)))
    m.add_lobe("back", kauri.Lambert(albedo=(0.25, 0.38, 0.15)))
    m.combine("diffuse", "coat", "front", "back")
    m.add_lobe("transmit", kauri.DiffuseTransmission(transmittance=(0.25, 0.55, 0.08)), weight=0.35)
    m.combine("core", "mix", "diffuse", "transmit")
    m.add_lobe("cuticle_bottom", kauri.RoughDielectric(ior=1.45, roughness=0.5))
    m.combine("lower", "coat", "core", "cuticle_bottom")
    m.add_lobe("cuticle_top", kauri.RoughDielectric(ior=1.45, roughness=0.25))
    m.combine("leaf", "coat", "cuticle_top", "lower")
    return m


def brushed_metal():
    return kauri.Conductor(metal="Al", roughness=0.35, anisotropy=0.85, name="brushed_aluminium")


def thin_glass():
    return kauri.ThinDielectric(ior=1.5, name="thin_glass")


def fabric():
    m = kauri.Material("velvet")
    m.add_lobe("fuzz", kauri.Sheen(color=(0.9, 0.5, 0.6), roughness=0.35))
    m.add_lobe("weave", kauri.Lambert(albedo=(0.35, 0.05, 0.12)))
    m.combine("fabric", "coat", "fuzz", "weave")
    return m


MATERIALS = [car_paint, wet_concrete, leaf, brushed_metal, thin_glass, fabric]


def build():
    s = kauri.Scene()
    floor = np.array([[-20, -0.96, -20], [20, -0.96, -20], [20, -0.96, 20], [-20, -0.96, 20]])
    checker = kauri.Lambert(albedo=(0.5, 0.5, 0.5), name="floor")
    s.add_mesh(floor, np.array([[0, 3, 2, 1]]), material=checker, name="floor")
    for i, make in enumerate(MATERIALS):
        row, col = divmod(i, 3)
        s.add_sphere(center=(-2.2 + 2.2 * col, 2.2 - 2.2 * row, 0), radius=0.95, material=make(),
                     name=make.__name__)
    # A backdrop with stripes, so transmission and reflection have something to show.
    back = np.array([[-20, -1.0, -3], [20, -1.0, -3], [20, 12, -3], [-20, 12, -3]])
    s.add_mesh(back, np.array([[0, 1, 2, 3]]), material=kauri.Lambert(albedo=(0.2, 0.25, 0.3)), name="backdrop")
    for k in range(-6, 7):
        P = np.array([[k - 0.15, -1.0, -2.99], [k + 0.15, -1.0, -2.99], [k + 0.15, 12, -2.99], [k - 0.15, 12, -2.99]])
        s.add_mesh(P, np.array([[0, 1, 2, 3]]), material=kauri.Lambert(albedo=(0.8, 0.75, 0.6)), name=f"stripe{k}")
    s.add_environment(color=(0.55, 0.65, 0.8), intensity=0.7)
    s.add_distant_light(direction=(-0.4, -0.8, -0.6), angle=2.0, intensity=4.0, temperature=5600, name="sun")
    P = np.array([[-1.5, 6, 2], [1.5, 6, 2], [1.5, 6, 5], [-1.5, 6, 5]])
    s.add_mesh(P, np.array([[0, 1, 2, 3]]), emission=kauri.Emission(intensity=6.0), name="softbox")
    s.set_camera(eye=(0, 1.2, 9.5), target=(0, 1.1, 0), fov=44, fov_axis="x")
    return s
