"""Pixel reconstruction: splatting (default) and filter importance sampling estimate the
same filtered image; splatting has lower per-pixel noise; bad values are refused."""
import numpy as np
import pytest

import kauri
from kauri import demo

RES = (24, 20)


def _renders(reconstruction, n, spp=4):
    scene = demo.build()
    return np.stack([kauri.render(scene, spp=spp, resolution=RES, seed=100 + i, max_depth=4,
                                  reconstruction=reconstruction).rgba[:, :, :3] for i in range(n)])


@pytest.fixture(scope="module")
def both():
    return _renders("splat", 12), _renders("filter_importance", 12)


def test_splat_and_filter_importance_agree_in_expectation(both):
    splat, fis = both
    # 4×4 block means over the interior (both estimators are consistent for the same
    # filter; they differ by noise and by the weighted estimator's O(1/N) ratio bias).
    def blocks(a):
        a = a[:, 2:18, 2:22]
        return a.reshape(a.shape[0], 4, 4, 5, 4, 3).mean(axis=(2, 4))
    bs, bf = blocks(splat), blocks(fis)
    diff = bs.mean(axis=0) - bf.mean(axis=0)
    se = np.sqrt(bs.var(axis=0, ddof=1) / len(bs) + bf.var(axis=0, ddof=1) / len(bf))
    z = diff / np.maximum(se, 1e-6)
    assert np.max(np.abs(z)) < 5, np.max(np.abs(z))
    assert abs(splat.mean() / fis.mean() - 1) < 0.02


def test_splatting_lowers_per_pixel_noise(both):
    splat, fis = both
    # Each sample reaches ~π(2σ)² ≈ 3 pixels' worth of weight: expect ~3× less variance.
    v_splat = splat.var(axis=0, ddof=1)[2:-2, 2:-2].mean()
    v_fis = fis.var(axis=0, ddof=1)[2:-2, 2:-2].mean()
    assert v_fis / v_splat > 1.8, (v_fis, v_splat)


@pytest.mark.parametrize("reconstruction", ["splat", "filter_importance"])
def test_each_reconstruction_is_deterministic_across_threads(reconstruction):
    scene = demo.build()
    a = kauri.render(scene, spp=3, resolution=(37, 23), seed=5, threads=1, reconstruction=reconstruction)
    b = kauri.render(scene, spp=3, resolution=(37, 23), seed=5, threads=2, reconstruction=reconstruction)
    assert np.array_equal(a.rgba, b.rgba)


def test_box_of_half_a_pixel_is_the_same_image_either_way():
    scene = demo.build()
    kw = dict(spp=2, resolution=(16, 12), seed=9, filter="box", filter_radius=0.5)
    a = kauri.render(scene, reconstruction="splat", **kw).rgba
    b = kauri.render(scene, reconstruction="filter_importance", **kw).rgba
    # Same sample positions (uniform in the pixel), one pixel each: equal up to rounding.
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)


def test_too_wide_filter_is_refused():
    with pytest.raises(ValueError, match="filter_radius"):
        kauri.render(demo.build(), spp=1, resolution=(8, 8), filter_radius=9)


def test_unknown_reconstruction_is_refused():
    with pytest.raises(ValueError, match="reconstruction"):
        kauri.render(demo.build(), spp=1, resolution=(8, 8), reconstruction="gather")
