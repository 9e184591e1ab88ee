"""render(path_lanes=True): a pixel's paths traced 8 at a time in vector lanes
(integrator/path_lanes.h) where the scene allows it. The bench's Cornell box, hangar,
textured room and environment-lit scene (Lambert meshes, image textures, analytic spheres,
triangle lights, an environment map) run in lanes and give the one-path-at-a-time image up
to float rounding, with the same rays; so does the glossy scene, whose gold and glass
spheres run in the lanes too (rough GGX conductors and dielectrics), and the same scene with
a rough silver floor for its only other surface. A scene of mirrors falls back, which the
statistics say."""
import os
import sys

import numpy as np
import pytest

import kauri

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
import peers  # noqa: E402
from scenes import cornell, envmap, glossy, hangar, textured  # noqa: E402


def _render(desc, lanes, res=24, spp=16):
    return kauri.render(peers.to_kauri(desc), spp=spp, resolution=(res, res), seed=3, threads=2, path_lanes=lanes)


@pytest.mark.parametrize("module", [cornell, hangar, textured, envmap, glossy],
                         ids=["cornell", "hangar", "textured", "envmap", "glossy"])
def test_lanes_give_the_scalar_image(module):
    desc = module.describe()
    a, b = _render(desc, False), _render(desc, True)
    assert not a.stats["path_lanes"] and b.stats["path_lanes"]
    # A path whose last-bit difference flips a comparison parts ways: a few rays in 10^4.
    assert abs(b.stats["rays"] / a.stats["rays"] - 1) < 2e-4
    x, y = a.rgba.astype(np.float64), b.rgba.astype(np.float64)
    assert np.abs(x - y).sum() / np.abs(x).sum() < 2e-4
    np.testing.assert_allclose(b.albedo, a.albedo, atol=1e-5)
    np.testing.assert_allclose(b.depth, a.depth, rtol=1e-6)


def test_scenes_without_lambert_surfaces_run_in_lanes():
    # A rough silver floor for the glossy scene's only diffuse surface: every surface a
    # conductor or a rough dielectric, all of them run across the lanes.
    desc = glossy.describe()
    desc["shapes"] = [dict(sh, conductor={"metal": "Ag", "alpha": 0.1}) if "diffuse" in sh else sh
                      for sh in desc["shapes"]]
    a, b = _render(desc, False), _render(desc, True)
    assert not a.stats["path_lanes"] and b.stats["path_lanes"]
    assert abs(b.stats["rays"] / a.stats["rays"] - 1) < 2e-4
    x, y = a.rgba.astype(np.float64), b.rgba.astype(np.float64)
    assert np.abs(x - y).sum() / np.abs(x).sum() < 2e-4


def test_scenes_without_lane_surfaces_fall_back():
    desc = glossy.describe()
    # Mirrors (α = 0: a specular bounce, which the lanes take lane by lane at most) everywhere.
    desc["shapes"] = [dict({k: v for k, v in sh.items() if k not in ("diffuse", "dielectric")},
                           conductor={"metal": "Ag", "alpha": 0.0})
                      if ("diffuse" in sh or "conductor" in sh or "dielectric" in sh) else sh
                      for sh in desc["shapes"]]
    out = _render(desc, True, res=8, spp=2)
    assert not out.stats["path_lanes"]


def test_path_lanes_are_on_by_default():
    out = kauri.render(peers.to_kauri(cornell.describe()), spp=2, resolution=(8, 8))
    assert out.stats["path_lanes"]
