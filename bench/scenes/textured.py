"""Textured diffuse surfaces: a Cornell-like room whose floor is a tiled checker texture
(repeated 4 × 4 times through the uv scale) and whose back wall carries a colour-gradient
texture with stripes, lit by one area light. Textures are generated here (linear sRGB,
row 0 = top of the image; uv (0, 0) at the first quad corner, the image's bottom-left)."""
import numpy as np


def checker(n=64, cells=8, a=(0.8, 0.75, 0.7), b=(0.15, 0.2, 0.3)):
    i = (np.arange(n) * cells // n)
    mask = ((i[:, None] + i[None, :]) % 2).astype(np.float32)[..., None]
    return (np.asarray(a, np.float32) * (1 - mask) + np.asarray(b, np.float32) * mask).astype(np.float32)


def stripes(width=96, height=48):
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    U, V = np.meshgrid(u, v)
    img = np.stack([0.2 + 0.6 * U, 0.25 + 0.5 * V, 0.7 - 0.5 * U], -1)
    band = (np.floor(U * 12) % 2 == 0)[..., None]
    return np.where(band, img, img * 0.4).astype(np.float32)


def describe():
    white = (0.73, 0.73, 0.73)
    return {
        "name": "textured",
        "color_space": "srgb",
        "shapes": [
            {"name": "floor", "quad": [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)],
             "diffuse": white, "texture": checker(), "uv_scale": 4},
            {"name": "back", "quad": [(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)],
             "diffuse": white, "texture": stripes(), "uv_scale": 1},
            {"name": "ceiling", "quad": [(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)], "diffuse": white},
            {"name": "left", "quad": [(-1, 0, 1), (-1, 0, -1), (-1, 2, -1), (-1, 2, 1)], "diffuse": (0.63, 0.065, 0.05)},
            {"name": "right", "quad": [(1, 0, -1), (1, 0, 1), (1, 2, 1), (1, 2, -1)], "diffuse": (0.14, 0.45, 0.091)},
            {"name": "ball", "sphere": ((0.3, 0.45, 0.1), 0.45), "diffuse": (0.6, 0.6, 0.6)},
            {"name": "light", "quad": [(-0.25, 1.99, -0.25), (0.25, 1.99, -0.25), (0.25, 1.99, 0.25),
                                       (-0.25, 1.99, 0.25)], "emission": (17.0, 17.0, 17.0)},
        ],
        "camera": {"eye": (0, 1, 3.85), "target": (0, 1, 0), "up": (0, 1, 0), "fov_x": 38.0},
    }
