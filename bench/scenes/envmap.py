"""A diffuse sphere on a ground quad lit only by an environment map: a synthetic sky
(horizon-to-zenith gradient plus a soft sun) generated here, lat-long with the Mitsuba
convention (u = atan2(x, −z)/2π, v = acos(y)/π) that both renderers share."""
import numpy as np


def sky(width=128, height=64):
    v = (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    U, V = np.meshgrid(u, v)
    theta, phi = V * np.pi, U * 2 * np.pi
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1)
    up = np.clip(d[..., 1], 0, 1)
    img = np.zeros((height, width, 3))
    img[...] = (0.35 + 0.4 * up)[..., None] * np.array([0.55, 0.7, 1.0])
    # Ground below the horizon, blended over ~15° (both renderers interpolate texels
    # bilinearly; peers.mitsuba_latlong maps kauri's row placement onto Mitsuba's).
    t = np.clip(-d[..., 1] / 0.25, 0, 1)[..., None]
    img = img * (1 - t) + t * np.array([0.12, 0.1, 0.08])
    sun_dir = np.array([0.5, 0.6, 0.62]) / np.linalg.norm([0.5, 0.6, 0.62])
    cosang = d @ sun_dir
    img += 30 * np.exp(-(1 - cosang) / 0.01)[..., None] * np.array([1.0, 0.9, 0.75])  # soft sun, ~8°
    return img.astype(np.float32)


def describe():
    return {
        "name": "envmap",
        "color_space": "srgb",
        "shapes": [
            {"name": "ground", "quad": [(-4, 0, 4), (4, 0, 4), (4, 0, -4), (-4, 0, -4)], "diffuse": (0.5, 0.5, 0.5)},
            {"name": "ball", "sphere": ((0, 1, 0), 1.0), "diffuse": (0.8, 0.3, 0.2)},
        ],
        "environment": sky(),
        "camera": {"eye": (0, 2.5, 6), "target": (0, 0.8, 0), "up": (0, 1, 0), "fov_x": 45.0},
    }
