"""Dense geometry, as production scenes have: a displaced sphere of about a million
triangles (flat-shaded, no vertex normals) on a diffuse floor, lit by an area light and a
constant sky. Traversal costs more here than on the other scenes' few primitives, so the
ray-replay section shows how close kauri comes to Embree's raw rate when rays are not cheap."""
import numpy as np


def blob_mesh(n_phi=1024, n_theta=512, radius=0.9, center=(0.0, 0.95, 0.0)):
    """Lat-long grid over the sphere with radial displacement; (positions (N, 3) float32,
    triangles (M, 3) int32). Rows at the poles give degenerate triangles, which both
    renderers ignore."""
    theta = np.linspace(0, np.pi, n_theta + 1)
    phi = np.linspace(0, 2 * np.pi, n_phi + 1)[:-1]
    T, P = np.meshgrid(theta, phi, indexing="ij")
    r = radius * (1 + 0.08 * np.sin(7 * T) * np.sin(9 * P) + 0.04 * np.sin(23 * T + 1) * np.cos(19 * P)
                  + 0.015 * np.sin(61 * T) * np.sin(57 * P + 2))
    x = r * np.sin(T) * np.cos(P) + center[0]
    y = r * np.cos(T) + center[1]
    z = r * np.sin(T) * np.sin(P) + center[2]
    pos = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(n_theta), np.arange(n_phi), indexing="ij")
    a = i * n_phi + j
    b = i * n_phi + (j + 1) % n_phi
    c = a + n_phi
    d = b + n_phi
    tris = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([b, c, d], -1).reshape(-1, 3)])
    return pos, tris.astype(np.int32)


def describe(n_phi=1024, n_theta=512):
    """The scene; a coarser grid (n_phi × n_theta cells, two triangles each) for quick tests."""
    return {
        "name": "displaced",
        "color_space": "srgb",
        "shapes": [
            {"name": "floor", "quad": [(-5, 0, 5), (5, 0, 5), (5, 0, -5), (-5, 0, -5)], "diffuse": (0.45, 0.45, 0.45)},
            {"name": "blob", "mesh": blob_mesh(n_phi, n_theta), "diffuse": (0.7, 0.45, 0.3)},
            {"name": "panel", "quad": [(-1.5, 3.5, -0.5), (-0.5, 3.5, -0.5), (-0.5, 3.5, 0.5), (-1.5, 3.5, 0.5)],
             "emission": (12.0, 12.0, 12.0)},
        ],
        "environment_color": (0.25, 0.3, 0.35),
        "camera": {"eye": (0, 2.0, 4.2), "target": (0, 0.9, 0), "up": (0, 1, 0), "fov_x": 45.0},
    }
