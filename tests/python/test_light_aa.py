"""Light antialiasing (render/light_aa.h): extra camera rays for the lights seen directly,
in the pixels where a probe finds their edges. The same image as without it within noise
(unbiased per sample; the splatted film's ratio estimator converges to the same limit),
less noisy where small bright lamps are seen, and without effect on the image where no
light is seen in Le_rgb."""
import os
import sys

import numpy as np
import pytest

import kauri
from kauri import Emission, Lambert, Scene, SceneError

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
import peers  # noqa: E402
from scenes import envmap, hangar  # noqa: E402


def _renders(scene, light_aa, runs, spp, res, **kw):
    return np.stack([np.asarray(kauri.render(scene, spp=spp, resolution=res, seed=300 + s, threads=2, aovs=False,
                                             light_aa=light_aa, **kw).rgba, np.float64)[..., :3]
                     for s in range(runs)])


def _blocks(x):
    h, w = x.shape[1] // 4 * 4, x.shape[2] // 4 * 4
    x = x[:, :h, :w]
    return x.reshape(x.shape[0], h // 4, 4, w // 4, 4, 3).mean(axis=(2, 4))


def _max_z(a, b):
    ba, bb = _blocks(a), _blocks(b)
    se = np.sqrt(ba.var(0, ddof=1) / len(ba) + bb.var(0, ddof=1) / len(bb))
    return np.abs((ba.mean(0) - bb.mean(0)) / np.maximum(se, 1e-9)).max()


def _relvar(x, ref):
    return (x.var(0, ddof=1) / (ref ** 2 + 0.01)).mean()


@pytest.mark.parametrize("reconstruction,filt", [("splat", "gaussian"), ("filter_importance", "gaussian"),
                                                  ("splat", "box")])
def test_hangar_lamps_agree_and_are_less_noisy(reconstruction, filt):
    scene = peers.to_kauri(hangar.describe())  # 144 small lamps seen from below
    # The box (radius 2) takes the film's general splat, the Gaussian the 8-sample group's.
    kw = dict(reconstruction=reconstruction, filter=filt, **peers.KAURI_PATH_LIMITS)
    off = _renders(scene, 0, 16, 32, (48, 48), **kw)
    on = _renders(scene, 4, 16, 32, (48, 48), **kw)
    assert _max_z(on, off) < 5
    assert abs(on.mean() / off.mean() - 1) < 0.01
    ref = (on.mean(0) + off.mean(0)) / 2
    # Where the lamps are seen, 4 extra rays per sample cut the coverage noise to well
    # under half (measured 0.28× splatted, 0.36× with filter importance sampling).
    lamps = ref.max(axis=-1) > 0.5
    v_on, v_off = on.var(0, ddof=1)[lamps].mean(), off.var(0, ddof=1)[lamps].mean()
    assert v_on < 0.5 * v_off, (v_on, v_off)
    if reconstruction == "splat" and filt == "gaussian":
        # That noise dominates the splatted image's error (0.45× per pixel at 64 × 64);
        # with filter importance sampling the paths' own noise is 3× larger and does.
        assert _relvar(on, ref) < 0.7 * _relvar(off, ref), (_relvar(on, ref), _relvar(off, ref))


def _spheres_scene(aperture=0.0, sky=0.0):
    """Small emissive spheres and a disk seen directly over a diffuse floor, optionally
    through a thin lens and against a constant sky (the probe then runs everywhere)."""
    s = Scene()
    s.add_mesh([(-4, 0, 4), (4, 0, 4), (4, 0, -4), (-4, 0, -4)], [(0, 1, 2), (0, 2, 3)],
               material=Lambert(albedo=(0.6, 0.6, 0.6), name="floor"), name="floor")
    for i, x in enumerate((-1.2, 0.0, 1.2)):
        s.add_sphere(center=(x, 0.8, 0), radius=0.06, emission=Emission(color=(1.0, 0.8, 0.6), intensity=30),
                     name=f"bulb{i}")
    s.add_disk(center=(0.5, 1.6, -0.5), normal=(0, 0, 1), radius=0.08,
               emission=Emission(color=(0.6, 0.8, 1.0), intensity=25), name="panel")
    if sky > 0:
        s.add_environment(color=(sky, sky, sky))
    s.set_camera(eye=(0, 1.2, 4), target=(0, 0.8, 0), fov=40, aperture_radius=aperture)
    return s


@pytest.mark.parametrize("aperture,sky", [(0.0, 0.0), (0.05, 0.0), (0.0, 20.0)])
def test_sphere_and_disk_lights_agree(aperture, sky):
    scene = _spheres_scene(aperture, sky)
    off = _renders(scene, 0, 12, 32, (40, 32))
    on = _renders(scene, 4, 12, 32, (40, 32))
    assert _max_z(on, off) < 5
    assert abs(on.mean() / off.mean() - 1) < 0.01
    ref = (on.mean(0) + off.mean(0)) / 2
    # Lamp pixels: those whose expected value reaches past what the floor and sky give.
    lamps = ref.max(axis=-1) > (sky + 2)
    v_on, v_off = on.var(0, ddof=1)[lamps].mean(), off.var(0, ddof=1)[lamps].mean()
    assert v_on < 0.7 * v_off, (v_on, v_off)
    # The sky never flags a pixel (its silhouettes are lit by the sky itself): elsewhere
    # the image is the same render. A flagged pixel is at most a pixel from where a lamp
    # shows (the mask's rounding) and its splats reach the default filter's radius of 2.
    far = ~_near(lamps, 1 + 2)
    assert np.array_equal(on[:, far], off[:, far])


def _near(mask, r):
    """Pixels within r of a set pixel (a splat's and a lamp edge's reach)."""
    out = mask.copy()
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            out |= np.roll(np.roll(mask, dy, axis=0), dx, axis=1)
    return out


def test_no_light_seen_in_rgb_leaves_the_image_unchanged():
    # The environment-map scene: its sky is an image, estimated spectrally, so nothing is
    # probed; the hangar seen from below its lamps, looking down: probed, never flagged.
    env = peers.to_kauri(envmap.describe())
    a = kauri.render(env, spp=8, resolution=(24, 16), seed=3, light_aa=0)
    b = kauri.render(env, spp=8, resolution=(24, 16), seed=3, light_aa=4)
    assert np.array_equal(a.rgba, b.rgba)
    assert a.stats["rays"] == b.stats["rays"]  # not even a probe
    d = hangar.describe()
    d["camera"] = {"eye": (0, 3, 6), "target": (0, 0, 2), "up": (0, 1, 0), "fov_x": 40.0}
    floor = peers.to_kauri(d)
    a = kauri.render(floor, spp=8, resolution=(24, 16), seed=3, light_aa=0)
    b = kauri.render(floor, spp=8, resolution=(24, 16), seed=3, light_aa=4)
    assert np.array_equal(a.rgba, b.rgba)
    # No lamp is in view, but the boxes of those above the camera cross its plane: every
    # pixel is probed, and none flagged.
    assert b.stats["rays"] > a.stats["rays"]
    assert b.stats["light_aa_pixels"] == 0


def test_extra_rays_are_counted_and_deterministic_across_threads():
    scene = peers.to_kauri(hangar.describe())
    a = kauri.render(scene, spp=8, resolution=(32, 32), seed=4, threads=1, light_aa=4)
    b = kauri.render(scene, spp=8, resolution=(32, 32), seed=4, threads=2, light_aa=4)
    assert np.array_equal(a.rgba, b.rgba)
    off = kauri.render(scene, spp=8, resolution=(32, 32), seed=4, threads=1, light_aa=0)
    # The probes of the pixels near lamps, plus 4 extra rays per sample in the flagged ones.
    flagged = a.stats["light_aa_pixels"]
    assert 0 < flagged < 32 * 32 and off.stats["light_aa_pixels"] == 0
    assert a.stats["rays"] - off.stats["rays"] >= flagged * 8 * 4 + flagged * 8


@pytest.mark.parametrize("bad", [-1, 65, 2.5, "4"])
def test_light_aa_is_checked(bad):
    scene = peers.to_kauri(hangar.describe())
    with pytest.raises((SceneError, ValueError, TypeError), match="light_aa"):
        kauri.render(scene, spp=1, resolution=(4, 4), light_aa=bad)


@pytest.mark.parametrize("bad", [-1, 65])
def test_light_aa_is_checked_below_python(bad):
    # The binding checks too (for callers of kauri._core), in render()'s argument order.
    scene = peers.to_kauri(hangar.describe())
    with pytest.raises(ValueError, match="light_aa"):
        kauri._core.render(scene._core, 4, 4, 1, 0, 1, 0.0, "zsobol", 16, 6, 8, 12, 0.0, "gaussian", 2.0, 0.5,
                           "splat", False, False, "tree", 4, bad, True)


def test_cli_refuses_a_bad_light_aa(tmp_path):
    from kauri import cli
    with pytest.raises(SystemExit) as e:
        cli.main(["render", "--light-aa", "-1", "-o", str(tmp_path / "x.exr")])
    assert e.value.code == 2


def test_progressive_passes_and_the_ray_replay_take_the_extra_rays():
    scene = peers.to_kauri(hangar.describe())
    # Passes of 1, 1, 2, 4, 8, 16 samples under a time limit it never reaches: each pixel is
    # probed once, on its first visit, keeps its flag, and its extra rays continue their
    # sequence pass after pass: the image is the one-pass render's up to float rounding.
    passes = kauri.render(scene, spp=32, resolution=(32, 32), seed=2, time_limit=1e6, light_aa=4)
    one_pass = kauri.render(scene, spp=32, resolution=(32, 32), seed=2, light_aa=4)
    off = kauri.render(scene, spp=32, resolution=(32, 32), seed=2, light_aa=0)
    assert passes.stats["spp"] == 32
    np.testing.assert_allclose(passes.rgba, one_pass.rgba, rtol=1e-4, atol=1e-5)
    assert passes.stats["rays"] == one_pass.stats["rays"]  # each pixel probed once, not per pass
    assert np.abs(one_pass.rgba - off.rgba).max() > 1e-3  # the extra rays did act
    r = kauri.ray_replay(scene, spp=4, resolution=(32, 32), threads=1, repeats=1, light_aa=4)
    assert r["hits_match"] and r["render_rays"] == r["closest_rays"] + r["shadow_rays"]
