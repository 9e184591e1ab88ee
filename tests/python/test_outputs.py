"""Outputs: EXR channels and metadata read back with the OpenEXR module, PNG preview,
determinism across thread counts, progressive stopping and the NaN guard."""
import os

import numpy as np
import pytest

import kauri
from kauri import demo


@pytest.fixture(scope="module")
def small_demo():
    return kauri.render(demo.build(), spp=8, resolution=(48, 40), seed=7)


def test_render_returns_beauty_and_aovs(small_demo):
    out = small_demo
    assert out.rgba.shape == (40, 48, 4) and out.rgba.dtype == np.float32
    assert out.albedo.shape == (40, 48, 3)
    assert out.normal.shape == (40, 48, 3)
    assert out.depth.shape == (40, 48)
    assert np.all(np.isfinite(out.rgba))
    # The room is open only towards the camera; the image centre sees geometry everywhere.
    alpha = out.rgba[:, :, 3]
    assert np.all((alpha >= 0) & (alpha <= 1))
    assert np.all(alpha[5:35, 8:40] == 1.0)
    n = np.linalg.norm(out.normal, axis=-1)
    np.testing.assert_allclose(n[n > 0], 1.0, atol=1e-4)
    # Albedo is estimated with the path's wavelengths, so it carries a little spectral noise.
    assert np.all((out.albedo >= -0.1) & (out.albedo <= 1.05))
    white_wall = out.albedo[10:20, 20:28].mean(axis=(0, 1))
    np.testing.assert_allclose(white_wall, 0.73, rtol=0.03)
    # Depth averages a pixel's own samples; alpha is splatted with the beauty, so a pixel
    # just outside the room can have a little alpha (from its neighbours) and no depth.
    hit = alpha == 1
    assert np.all(out.depth[hit] > 0) and np.all(np.isfinite(out.depth[hit]))
    assert np.all(np.isinf(out.depth[alpha == 0]))
    assert np.all(alpha[np.isfinite(out.depth)] > 0)
    assert out.stats["spp"] == 8 and out.stats["nan_samples"] == 0
    assert out.stats["rays"] >= out.stats["samples"]


def test_beauty_without_aovs_is_identical(small_demo, tmp_path):
    # aovs=False skips albedo, normal and depth; the AOVs draw no samples, so the beauty
    # must be bit-identical to the render with them, and the EXR holds RGBA alone.
    out = kauri.render(demo.build(), spp=8, resolution=(48, 40), seed=7, aovs=False)
    assert out.albedo is None and out.normal is None and out.depth is None
    np.testing.assert_array_equal(out.rgba, small_demo.rgba)
    OpenEXR = pytest.importorskip("OpenEXR")
    path = tmp_path / "beauty.exr"
    out.write_exr(str(path))
    with OpenEXR.File(str(path), separate_channels=True) as f:
        assert set(f.channels()) == {"R", "G", "B", "A"}
        np.testing.assert_array_equal(f.channels()["G"].pixels, out.rgba[:, :, 1])


def test_colour_bleeding_is_visible(small_demo):
    # Left wall red, right wall green: the white floor near each wall picks up its colour.
    rgb = small_demo.rgba[:, :, :3]
    left, right = rgb[30:38, 4:10].mean(axis=(0, 1)), rgb[30:38, 38:44].mean(axis=(0, 1))
    assert left[0] > left[1] and right[1] > right[0]


def test_exr_channels_and_metadata(small_demo, tmp_path):
    OpenEXR = pytest.importorskip("OpenEXR")
    path = tmp_path / "out.exr"
    small_demo.write_exr(str(path), scene_name="demo")
    assert not [p for p in os.listdir(tmp_path) if ".tmp-" in p], "temporary file left behind"
    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = f.header()
        channels = f.channels()
        names = set(channels)
        assert {"R", "G", "B", "A", "albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z", "Z"} <= names
        np.testing.assert_array_equal(channels["R"].pixels, small_demo.rgba[:, :, 0])
        np.testing.assert_array_equal(channels["N.Y"].pixels, small_demo.normal[:, :, 1])
        np.testing.assert_array_equal(channels["Z"].pixels, small_demo.depth)
        assert header["kauri:spp"] == 8
        assert header["colorSpace"] == "acescg"
        assert "kauri:version" in header and "kauri:renderTime" in header
        chroma = header["chromaticities"]
        np.testing.assert_allclose(np.asarray(chroma)[:2], [0.713, 0.293], atol=1e-6)


def test_png_preview(small_demo, tmp_path):
    path = tmp_path / "out.png"
    small_demo.write_png(str(path))
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_unwritable_output_raises(small_demo, tmp_path):
    with pytest.raises(RuntimeError, match="could not write"):
        small_demo.write_exr(str(tmp_path / "missing_dir" / "x.exr"))


@pytest.mark.parametrize("sampler", ["zsobol", "sobol", "independent"])
def test_same_seed_same_image_for_any_thread_count(sampler):
    scene = demo.build()
    a = kauri.render(scene, spp=6, resolution=(40, 32), seed=3, threads=1, sampler=sampler)
    b = kauri.render(scene, spp=6, resolution=(40, 32), seed=3, threads=2, sampler=sampler)
    assert np.array_equal(a.rgba, b.rgba) and np.array_equal(a.albedo, b.albedo)
    assert np.array_equal(a.depth, b.depth)
    c = kauri.render(scene, spp=6, resolution=(40, 32), seed=4, threads=2, sampler=sampler)
    assert not np.array_equal(a.rgba, c.rgba)


def test_time_limit_stops_at_a_pass_boundary():
    out = kauri.render(demo.build(), spp=100000, resolution=(32, 32), time_limit=0.5)
    assert 1 <= out.stats["spp"] < 100000
    assert out.stats["seconds"] < 30
    # Passes of 1, 1, 2, 4, 8, 16, 16, ... samples: the render stops at a power of two up to
    # 16, then at a multiple of 16.
    spp = out.stats["spp"]
    assert spp in (1, 2, 4, 8) or spp % 16 == 0, spp


def test_passes_change_only_the_order_of_the_film_sums():
    # A render without a time limit is one pass; with one it runs in passes of growing size
    # (stopping at the last if time allows). The same samples reach the film either way, in
    # another order of the film's sums: equal up to float rounding.
    scene = demo.build()
    one = kauri.render(scene, spp=24, resolution=(24, 20), seed=2, threads=2)
    passes = kauri.render(scene, spp=24, resolution=(24, 20), seed=2, threads=2, time_limit=1e6)
    assert one.stats["spp"] == passes.stats["spp"] == 24
    np.testing.assert_allclose(passes.rgba, one.rgba, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(passes.albedo, one.albedo, rtol=1e-5, atol=1e-7)


def test_clamp_only_reduces_indirect_light():
    scene = demo.build()
    free = kauri.render(scene, spp=8, resolution=(32, 32), seed=1)
    clamped = kauri.render(scene, spp=8, resolution=(32, 32), seed=1, clamp=0.05)
    # The clamp bounds each sample's indirect luminance, so per-pixel luminance can only drop
    # (single channels may rise: a sample's ACEScg components can be negative).
    ap1_to_y = np.array([0.2722287, 0.6740818, 0.0536895])
    y_free, y_clamped = free.rgba[:, :, :3] @ ap1_to_y, clamped.rgba[:, :, :3] @ ap1_to_y
    assert y_clamped.sum() < y_free.sum()
    assert np.all(y_clamped <= y_free + 1e-5)
