#!/usr/bin/env python3
"""Training workload for kauri's profile-guided build (scripts/pgo_build).

An instrumented kauri (KAURI_PGO=generate) runs this script once; GCC then compiles the
release build with the branch and call counts it recorded (KAURI_PGO=use). A profile
only steers code layout, inlining and unrolling; images are the same as without it up
to floating-point contraction.

The scenes are our own, built through the public API, and deliberately not the peer
benchmark's (bench/scenes/): a profile trained on the benchmark would flatter it. They
cover what production scenes exercise: Lambert, Oren-Nayar, smooth and rough dielectric
(with dispersion), rough and anisotropic conductors, thin glass, diffuse transmission,
sheen and coated layers, image textures, area/point/spot/distant/environment lights,
hundreds of small emitters (light tree), dense meshes, instances, both samplers, AOVs
on and off and both film reconstructions. About 10 s on 2 cores when instrumented.
"""
from __future__ import annotations

import sys
import time

import numpy as np

import kauri
from kauri import demo
from kauri.demo import _quad


def _box(half, height, offset=(0.0, 0.0, 0.0)):
    """An axis-aligned box standing on y = 0 (quads facing out): positions, indices."""
    V = np.array([[x, y, z] for x in (-half, half) for y in (0, height) for z in (-half, half)], np.float32)
    F = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]], np.uint32)
    return V + np.asarray(offset, np.float32), F


def _checker(n=64, squares=8):
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    odd = ((i * squares // n + j * squares // n) % 2).astype(np.float32)
    img = np.empty((n, n, 3), np.float32)
    img[..., 0] = 0.15 + 0.6 * odd
    img[..., 1] = 0.2 + 0.4 * odd
    img[..., 2] = 0.1 + 0.2 * (1 - odd)
    return img


def _sky(h=32, w=64):
    """Lat-long sky: blue zenith, warm horizon, a small bright sun."""
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    V, U = np.meshgrid(v, u, indexing="ij")
    img = np.stack([0.3 + 0.5 * V, 0.45 + 0.3 * V, 0.9 - 0.3 * V], -1).astype(np.float32)
    sun = (np.abs(U - 0.3) < 0.03) & (np.abs(V - 0.3) < 0.04)
    img[sun] = (60.0, 55.0, 45.0)
    return img


def _bumpy_plane(n=160, size=3.0, y=0.0):
    """A displaced height field of 2 n² triangles, flat-shaded (no normals)."""
    t = np.linspace(-size / 2, size / 2, n + 1)
    X, Z = np.meshgrid(t, t, indexing="ij")
    Y = y + 0.04 * np.sin(9 * X) * np.cos(7 * Z) + 0.02 * np.sin(23 * X + 13 * Z)
    P = np.stack([X, Y, Z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c, d = a + 1, a + n + 1, a + n + 2
    return P, np.concatenate([np.stack([a, b, c], -1), np.stack([b, d, c], -1)]).astype(np.uint32)


def studio() -> kauri.Scene:
    """Textured and bumpy floor, spheres of every glossy kind, a sky image and a spot light."""
    s = kauri.Scene()
    P, I = _bumpy_plane()
    s.add_mesh(P, I, material=kauri.OrenNayar(albedo=(0.5, 0.45, 0.4), roughness=0.6, name="ground"), name="ground")
    P, I = _quad((-1.5, 0.001, 1.5), (1.5, 0.001, 1.5), (1.5, 0.001, -1.5), (-1.5, 0.001, -1.5))
    uv = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], np.float32)
    s.add_mesh(P * 0.5, I, uvs=uv, name="rug",
               material=kauri.Lambert(albedo=kauri.ImageTexture(_checker(), name="checker"), name="rug"))
    coated = kauri.Material("coated_copper")
    coated.add_lobe("metal", kauri.Conductor(metal="Cu", roughness=0.4))
    coated.add_lobe("clear", kauri.Dielectric(ior=1.5))
    coated.combine("paint", "coat", "clear", "metal")
    velvet = kauri.Material("velvet")
    velvet.add_lobe("base", kauri.Lambert(albedo=(0.4, 0.05, 0.1)))
    velvet.add_lobe("fuzz", kauri.Sheen(color=(0.9, 0.8, 0.8), roughness=0.3))
    velvet.combine("cloth", "coat", "fuzz", "base")
    spheres = [
        (kauri.RoughDielectric(ior=1.45, roughness=0.15, name="frosted"), (-0.9, 0.3, 0.0)),
        (kauri.Conductor(metal="Ag", roughness=0.08, name="silver"), (-0.3, 0.3, 0.4)),
        (kauri.Conductor(metal="Al", roughness=0.3, anisotropy=0.6, name="brushed"), (0.3, 0.3, -0.3)),
        (coated, (0.9, 0.3, 0.2)),
        (velvet, (0.0, 0.3, -0.9)),
        (kauri.Dielectric(ior=1.6, abbe=30.0, name="flint"), (0.5, 0.3, 0.9)),
    ]
    for k, (m, c) in enumerate(spheres):
        s.add_sphere(center=c, radius=0.28, material=m, name=f"sphere{k}")
    s.add_environment(image=_sky(), intensity=0.5)
    s.add_spot_light((1.5, 2.5, 1.5), (-0.5, -1, -0.5), cone_angle=25, intensity=40.0)
    s.set_camera(eye=(0.3, 1.6, 4.2), target=(0, 0.25, 0), fov=45)
    return s


def lamps() -> kauri.Scene:
    """A ceiling of 12 × 12 small emitters over a diffuse room with instanced boxes."""
    s = kauri.Scene()
    grey = kauri.Lambert(albedo=(0.6, 0.6, 0.6), name="grey")
    for name, q in {"floor": ((-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)),
                    "back": ((-3, 0, -3), (3, 0, -3), (3, 3, -3), (-3, 3, -3)),
                    "ceiling": ((-3, 3, -3), (3, 3, -3), (3, 3, 3), (-3, 3, 3))}.items():
        P, I = _quad(*q)
        s.add_mesh(P, I, material=grey, name=name)
    for i in range(12):
        for j in range(12):
            x, z = -2.75 + 0.5 * i, -2.75 + 0.5 * j
            P, I = _quad((x - 0.08, 2.99, z - 0.08), (x + 0.08, 2.99, z - 0.08), (x + 0.08, 2.99, z + 0.08),
                         (x - 0.08, 2.99, z + 0.08))
            hue = ((i * 7 + j * 3) % 5) / 4
            s.add_mesh(P, I, emission=kauri.Emission(color=(1.0, 0.6 + 0.4 * hue, 0.4 + 0.6 * (1 - hue)),
                                                     intensity=30.0), name=f"lamp{i}_{j}")
    box = s.add_group("box")
    s.add_mesh(*_box(0.3, 0.6), material=kauri.Lambert(albedo=(0.7, 0.3, 0.2), name="brick"), name="box_mesh", group=box)
    for k in range(9):
        M = np.eye(4, dtype=np.float32)
        M[0, 3], M[2, 3] = -2 + 2 * (k % 3), -2 + 2 * (k // 3)
        s.add_instance(box, M, name=f"box{k}")
    s.add_disk(center=(0, 1.2, 0), normal=(0, 1, 0), radius=0.4,
               material=kauri.ThinDielectric(ior=1.5, name="pane"), name="pane")
    s.add_mesh(*_quad((1, 0, 1.5), (2, 0, 1.5), (2, 1.5, 1.5), (1, 1.5, 1.5)),
               material=kauri.DiffuseTransmission(transmittance=(0.6, 0.6, 0.5), name="paper"), name="screen")
    s.add_point_light((0, 1.5, 2.0), intensity=3.0)
    s.add_distant_light((0.3, -1, -0.2), angle=2.0, intensity=0.5)
    s.set_camera(eye=(0, 1.5, 5.5), target=(0, 1.0, 0), fov=55)
    return s


def loft() -> kauri.Scene:
    """Diffuse interior lit by one window-sized area light: the most common production
    case (Lambert everywhere, a textured floor), so it takes the largest share of samples."""
    s = kauri.Scene()
    walls = {"floor": ((-2, 0, 2), (2, 0, 2), (2, 0, -2), (-2, 0, -2)),
             "ceiling": ((-2, 2.5, -2), (2, 2.5, -2), (2, 2.5, 2), (-2, 2.5, 2)),
             "back": ((-2, 0, -2), (2, 0, -2), (2, 2.5, -2), (-2, 2.5, -2)),
             "left": ((-2, 0, 2), (-2, 0, -2), (-2, 2.5, -2), (-2, 2.5, 2)),
             "right": ((2, 0, -2), (2, 0, 2), (2, 2.5, 2), (2, 2.5, -2))}
    paint = {"left": (0.2, 0.35, 0.6), "right": (0.7, 0.6, 0.2)}
    for name, q in walls.items():
        P, I = _quad(*q)
        if name == "floor":
            uv = np.array([[0, 0], [3, 0], [3, 3], [0, 3]], np.float32)
            s.add_mesh(P, I, uvs=uv, name=name, material=kauri.Lambert(
                albedo=kauri.ImageTexture(_checker(squares=16), name="tiles"), name="tiles"))
        else:
            s.add_mesh(P, I, material=kauri.Lambert(albedo=paint.get(name, (0.75, 0.75, 0.7)), name=name), name=name)
    for k, (x, z) in enumerate(((-0.8, -0.6), (0.9, 0.3))):
        s.add_mesh(*_box(0.4, 0.9, (x, 0, z)), name=f"crate{k}",
                   material=kauri.Lambert(albedo=(0.55, 0.4, 0.3), name=f"crate{k}"))
    P, I = _quad((-0.6, 2.49, -0.4), (0.6, 2.49, -0.4), (0.6, 2.49, 0.4), (-0.6, 2.49, 0.4))
    s.add_mesh(P, I, emission=kauri.Emission(color=(1.0, 0.9, 0.8), intensity=12.0), name="skylight")
    s.set_camera(eye=(0.2, 1.3, 4.5), target=(0, 0.9, 0), fov=50)
    return s


def main() -> int:
    t0 = time.perf_counter()
    jobs = [
        (loft(), dict(spp=32, resolution=(96, 72), aovs=False)),
        (loft(), dict(spp=8, resolution=(64, 48))),
        (demo.build(), dict(spp=16, resolution=(96, 72))),
        (demo.build(), dict(spp=8, resolution=(64, 48), aovs=False)),
        (studio(), dict(spp=8, resolution=(96, 72), aovs=False)),
        (studio(), dict(spp=4, resolution=(48, 36), sampler="sobol", reconstruction="filter_importance")),
        (lamps(), dict(spp=8, resolution=(96, 72), aovs=False)),
        (lamps(), dict(spp=4, resolution=(48, 36), sampler="independent", light_sampler="power")),
    ]
    for k, (scene, kw) in enumerate(jobs):
        kauri.render(scene, seed=k, threads=2, **kw)
    print(f"pgo_train: {len(jobs)} renders in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
