"""Renders docs/images/light_aa_hangar.png: the bench hangar's lamps at 16 spp without
and with light antialiasing (render(light_aa=0 / 4)), beside a 1024-spp reference, with the
render times and relMSE against the reference. Usage: python scripts/light_aa_figure.py"""
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "bench"))
import kauri  # noqa: E402
import peers  # noqa: E402
from scenes import hangar  # noqa: E402

RES, SPP, REF_SPP, ZOOM = (160, 64), 16, 1024, 4


def render(scene, spp, light_aa, seed, repeats=1):
    """The image and the best of `repeats` render times (the same seed: the same image)."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        img = kauri.render(scene, spp=spp, resolution=RES, seed=seed, threads=2, aovs=False, light_aa=light_aa,
                           **peers.KAURI_PATH_LIMITS).rgba[..., :3]
        best = min(best, time.perf_counter() - t0)
    return np.asarray(img, np.float64), best


def to_srgb(x):
    x = x / (1 + x)  # Reinhard: the lamps (radiance ~8) keep their edges' gradations
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def main():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    desc = hangar.describe()
    desc["camera"] = {"eye": (0, 3.2, 6), "target": (0, 5.0, -2), "up": (0, 1, 0), "fov_x": 50.0}
    scene = peers.to_kauri(desc)
    ref, _ = render(scene, REF_SPP, 4, 99)
    panels = []
    for aa in (0, 4):
        img, t = render(scene, SPP, aa, 1, repeats=5)
        rel = np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))
        panels.append((img, f"light_aa={aa}: {SPP} spp, {1e3 * t:.0f} ms, relMSE {rel:.2e}"))
    panels.append((ref, f"reference, {REF_SPP} spp"))
    fig, axes = plt.subplots(3, 1, figsize=(RES[0] * ZOOM / 150, 3 * (RES[1] * ZOOM / 150 + 0.3)), dpi=150)
    for ax, (img, title) in zip(axes, panels):
        ax.imshow(to_srgb(img), interpolation="nearest")
        ax.set_title(title, fontsize=7)
        ax.axis("off")
    fig.tight_layout()
    out = os.path.join(HERE, "..", "docs", "images", "light_aa_hangar.png")
    fig.savefig(out + ".tmp.png")
    os.replace(out + ".tmp.png", out)  # written whole or not at all
    print(out)


if __name__ == "__main__":
    main()
