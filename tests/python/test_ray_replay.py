"""Embree ray replay (bench's 'closeness to the limit'): the recorded rays are exactly the
render's ray queries, and replaying them through Embree alone finds the same hits."""
import os
import sys

import pytest

import kauri

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
import peers  # noqa: E402
from scenes import cornell, glossy, textured  # noqa: E402


@pytest.mark.parametrize("mod", [cornell, glossy], ids=["cornell", "glossy"])
def test_replay_sees_the_renders_rays_and_hits(mod):
    scene = peers.to_kauri(mod.describe())
    r = kauri.ray_replay(scene, spp=2, resolution=(32, 32), seed=7, threads=2, repeats=1)
    # Recording retraces the render's paths with the same seed: same number of queries.
    assert r["complete"] and r["closest_rays"] + r["shadow_rays"] == r["render_rays"]
    assert r["closest_rays"] >= 32 * 32 * 2  # at least the camera rays
    assert r["shadow_rays"] > 0
    # Embree alone, in parallel, reproduces every recorded hit / occlusion count.
    assert r["hits_match"], r
    assert r["embree_rays_per_second"] > 0 and r["render_rays_per_second"] > 0


def test_replay_recording_cap_is_reported():
    scene = peers.to_kauri(cornell.describe())
    r = kauri.ray_replay(scene, spp=2, resolution=(32, 32), max_rays=1000, repeats=1)
    assert not r["complete"]
    assert r["closest_rays"] + r["shadow_rays"] == 1000
    assert r["hits_match"]


def test_replay_bad_input():
    with pytest.raises(kauri.SceneError, match="ray_replay: the scene has no camera"):
        kauri.ray_replay(kauri.Scene())


@pytest.mark.parametrize("mod", [cornell, textured], ids=["cornell", "textured (a direct sphere)"])
def test_packet_replay_finds_the_same_hits(mod):
    scene = peers.to_kauri(mod.describe())
    r = kauri.ray_replay(scene, spp=2, resolution=(24, 24), seed=3, threads=2, repeats=1, packets=(8, 16))
    assert r["hits_match"]
    assert sorted(r["packet_replay"]) == [8, 16]
    for width, p in r["packet_replay"].items():
        assert p["hits_match"], (width, p)
        assert p["embree_rays_per_second"] > 0 and p["speedup_over_single"] > 0


def test_packet_replay_bad_widths():
    scene = peers.to_kauri(cornell.describe())
    with pytest.raises(ValueError, match="packets': widths must be 8 or 16, got \\[4\\]"):
        kauri.ray_replay(scene, spp=1, resolution=(8, 8), packets=(4,))
    with pytest.raises(ValueError, match="expected a sequence of packet widths"):
        kauri.ray_replay(scene, spp=1, resolution=(8, 8), packets=8)
