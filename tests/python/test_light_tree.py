"""The light tree (next-event estimation's light choice in many-light scenes) renders the
same image as choosing by power, with less noise where the lights are many and small."""
import os
import sys

import numpy as np
import pytest

import kauri

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench"))
import peers  # noqa: E402
from scenes import hangar  # noqa: E402


def _renders(scene, light_sampler, runs, spp=64, res=64):
    return np.stack([np.asarray(kauri.render(scene, spp=spp, resolution=(res, res), seed=100 + s, threads=2,
                                             aovs=False, light_sampler=light_sampler,
                                             **peers.KAURI_PATH_LIMITS).rgba, np.float64)[..., :3]
                     for s in range(runs)])


def test_tree_and_power_agree_and_the_tree_is_less_noisy_on_the_hangar():
    scene = peers.to_kauri(hangar.describe())  # 144 lamps = 288 emitting triangles
    tree, power = _renders(scene, "tree", 16), _renders(scene, "power", 16)
    # Unbiased: 4x4-pixel block means agree within noise (z-test, variance from the runs).
    def blocks(x):
        return x.reshape(x.shape[0], 16, 4, 16, 4, 3).mean(axis=(2, 4))
    bt, bp = blocks(tree), blocks(power)
    se = np.sqrt(bt.var(0, ddof=1) / len(bt) + bp.var(0, ddof=1) / len(bp))
    z = (bt.mean(0) - bp.mean(0)) / np.maximum(se, 1e-9)
    assert np.abs(z).max() < 5, np.abs(z).max()
    assert abs(tree.mean() / power.mean() - 1) < 0.01
    # Less noise at equal samples: the tree picks the lamps that light each point.
    ref = (tree.mean(0) + power.mean(0)) / 2
    def relvar(x):
        return (x.var(0, ddof=1) / (ref ** 2 + 0.01)).mean()
    assert relvar(tree) < 0.85 * relvar(power), (relvar(tree), relvar(power))


def test_light_sampler_is_checked():
    scene = peers.to_kauri(hangar.describe())
    with pytest.raises(ValueError, match="light_sampler.*'tree' or 'power'"):
        kauri.render(scene, spp=1, resolution=(4, 4), light_sampler="bvh")
