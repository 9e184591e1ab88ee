"""The pure functions of bench/suite.py (no rendering): the relMSE estimator, efficiency and
time-to-error, the ratio table, the block z-test and the scene registry."""
import importlib.util
import math
import os
import sys

import numpy as np
import pytest

_PATH = os.path.join(os.path.dirname(__file__), "..", "..", "bench", "suite.py")
_spec = importlib.util.spec_from_file_location("bench_suite", _PATH)
suite = importlib.util.module_from_spec(_spec)
sys.modules["bench_suite"] = suite  # dataclasses look their module up there
_spec.loader.exec_module(suite)


def test_relmse_estimator_is_unbiased_for_a_known_variance():
    rng = np.random.default_rng(1234)
    h, w, c, k = 16, 16, 3, 4
    ref = rng.uniform(0.0, 2.0, (h, w, c))
    sigma = rng.uniform(0.01, 0.5, (h, w, c))
    expected = np.mean(sigma ** 2 / (ref ** 2 + suite.REL_EPS))
    # Few renders per estimate (K = 4): ddof = 1 keeps the mean of the estimates on target,
    # the biased (ddof = 0) variance would be low by (K - 1) / K = 25%.
    est = [suite.relmse_from_runs(ref + sigma * rng.standard_normal((k, h, w, c)), ref) for _ in range(400)]
    assert np.mean(est) == pytest.approx(expected, rel=0.02)
    # The estimate does not depend on the (unknown) expected image, only on the spread.
    runs = ref + sigma * rng.standard_normal((k, h, w, c))
    assert suite.relmse_from_runs(runs + 3.0, ref) == pytest.approx(suite.relmse_from_runs(runs, ref))


def test_relmse_needs_two_renders():
    with pytest.raises(ValueError):
        suite.relmse_from_runs(np.zeros((1, 2, 2, 3)), np.zeros((2, 2, 3)))


def test_efficiency_and_time_to_error_for_an_ideal_ladder():
    spp = [4, 16, 64, 256]
    t = [0.05 + 0.01 * s for s in spp]          # a fixed cost per call, then linear in spp
    c = 0.3
    err = [c / x for x in t]                     # relMSE exactly proportional to 1 / t
    err[0] *= 10                                 # the 4-spp rung is below min_spp: ignored
    assert suite.efficiency(spp, err, t, min_spp=16) == pytest.approx(c)
    assert suite.time_to_error(c, 1e-3) == pytest.approx(300.0)
    assert suite.loglog_slope(t[1:], err[1:]) == pytest.approx(-1.0)


def test_efficiency_is_the_geometric_mean_of_relmse_times_t():
    spp, err, t = [16, 64], [0.02, 0.004], [0.1, 0.4]   # products 2e-3 and 1.6e-3
    assert suite.efficiency(spp, err, t) == pytest.approx(math.sqrt(2e-3 * 1.6e-3))
    with pytest.raises(ValueError):
        suite.efficiency([4], [0.1], [0.01], min_spp=16)


def test_ratio_table_and_geometric_means():
    times = {"a": {"kauri": 2.0, "x": 1.0, "y": 8.0},
             "b": {"kauri": 1.0, "x": 4.0, "y": None},
             "c": {"x": 1.0}}                      # no kauri: left out
    r = suite.ratio_table(times)
    assert r == {"a": {"x": 0.5, "y": 4.0}, "b": {"x": 4.0, "y": None}}
    gm = suite.geometric_means(r)
    assert gm["x"] == pytest.approx(math.sqrt(0.5 * 4.0))
    assert gm["y"] == pytest.approx(4.0)
    md = suite.md_table(["scene", "x / kauri"], [["a", suite.fmt_g(r["a"]["x"])], ["b", suite.fmt_g(None)]])
    assert md.splitlines()[0].startswith("| scene") and "| 0.5 " in md and "–" in md


def test_block_z_detects_a_bias_and_not_noise():
    rng = np.random.default_rng(7)
    k = 1.0 + 0.1 * rng.standard_normal((16, 36, 36, 3))
    m = 1.0 + 0.1 * rng.standard_normal((16, 36, 36, 3))
    z = suite.block_z(k, m)
    assert z.shape == (4, 4, 3) and np.abs(z).max() < 5
    assert np.abs(suite.block_z(k * 1.05, m)).max() > 5
    # Blocks without noise (a sky seen directly): the fits' floor of 0.2% of the mean.
    flat = np.ones((16, 36, 36, 3)) + 1e-7 * rng.standard_normal((16, 36, 36, 3))
    assert np.abs(suite.block_z(flat * 1.001, flat)).max() < 5
    assert np.abs(suite.block_z(flat * 1.005, flat)).max() > 5
    assert suite.mean_rel_diff(k.mean(0) * 1.02, k.mean(0)) == pytest.approx([0.02] * 3)
    # Per-render image means have sd 0.1 / 36 here: the SE of the difference of two 16-run means.
    assert suite.mean_rel_diff_se(k, m) == pytest.approx([0.1 / 36 * math.sqrt(2 / 16)] * 3, rel=0.4)


def test_relmse_between_mean_images_and_its_noise_level():
    rng = np.random.default_rng(3)
    a = 0.5 + 0.05 * rng.standard_normal((20, 8, 8, 3))
    b = 0.5 + 0.05 * rng.standard_normal((20, 8, 8, 3))
    rel, noise = suite.relmse_between(a, b)
    # Unbiased: relMSE of the two means is at the noise level (factor ~1 up to sampling).
    assert np.all(rel < 3 * noise) and np.all(rel > noise / 3)
    rel_biased, _ = suite.relmse_between(a * 1.2, b)
    assert np.all(rel_biased > 10 * noise)


def test_block_averages_for_the_second_error_scale():
    img = np.arange(8 * 8 * 3, dtype=float).reshape(1, 8, 8, 3)
    blocks = suite.to_blocks(img)
    assert blocks.shape == (1, 2, 2, 3)
    assert blocks[0, 0, 0, 0] == pytest.approx(img[0, :4, :4, 0].mean())


def test_scene_registry_has_describable_scenes():
    assert {"cornell", "glossy", "hangar", "envmap"} <= set(suite.SCENES)
    for module in suite.SCENES.values():
        assert callable(module.describe)


def test_marginal_efficiency_removes_a_fixed_per_call_cost():
    # t = 0.3 s + 5 ms per sample, relMSE = 0.2 / spp: the marginal figure is the top rung's
    # relMSE times its sampling time alone, and the overhead comes back.
    spp = [4, 16, 64, 256]
    t = [0.3 + 0.005 * s for s in spp]
    err = [0.2 / s for s in spp]
    c, overhead = suite.marginal_efficiency(spp, err, t)
    assert c == pytest.approx(0.2 / 256 * 0.005 * 256)
    assert overhead == pytest.approx(0.3)
    assert suite.efficiency(spp, err, t) > c  # the fitted efficiency carries the overhead


def test_interleaved_order_runs_every_renderer_once_per_round_in_rotated_order():
    rs = ["kauri", "scalar_rgb", "llvm_ad_rgb"]
    order = suite.interleaved_order(rs, 4)
    assert len(order) == 12
    for k in range(4):
        this_round = [r for (j, r) in order[3 * k:3 * k + 3]]
        assert all(j == k for (j, _) in order[3 * k:3 * k + 3])
        assert sorted(this_round) == sorted(rs)
        assert this_round[0] == rs[k % 3]  # the first place rotates
    # no renderer always follows the same one
    followers = {r: {order[i + 1][1] for i in range(len(order) - 1) if order[i][1] == r} for r in rs}
    assert all(len(f) >= 1 for f in followers.values())
    assert suite.interleaved_order(["kauri"], 3) == [(0, "kauri"), (1, "kauri"), (2, "kauri")]


def test_measure_rung_interleaves_renders_and_drops_a_failing_renderer():
    calls = []

    class FakeRenderers:
        def render(self, renderer, desc, spp, res, seed, mitsuba_sampler="independent"):
            assert mitsuba_sampler == suite.SPEED_MITSUBA_SAMPLER  # Mitsuba converges as fast as it can
            calls.append((renderer, seed))
            if renderer == "broken" and seed < 999_000:
                raise RuntimeError("boom")
            return np.full((2, 2, 3), seed, np.float64), suite.Call(0.01 if renderer == "kauri" else 0.02, 0.01)

    done, failed = suite._measure_rung(FakeRenderers(), ["kauri", "peer", "broken"], {}, 4, 2, 3, seed0=100)
    assert set(done) == {"kauri", "peer"} and set(failed) == {"broken"}
    timed = [c for c in calls if c[1] < 999_000]
    # round 0: kauri, peer, broken (fails, then is dropped); round 1 starts with peer.
    assert timed == [("kauri", 100), ("peer", 100), ("broken", 100), ("peer", 101), ("kauri", 101),
                     ("kauri", 102), ("peer", 102)]
    imgs, rung = done["kauri"]
    assert imgs.shape == (3, 2, 2, 3) and list(imgs[:, 0, 0, 0]) == [100, 101, 102]
    assert rung["spp"] == 4 and rung["time"] == pytest.approx(0.01) and rung["warmups"] == 1
    assert suite.round_time_ratios(done["peer"][1]["times"], rung["times"]) == pytest.approx((2.0, 2.0, 2.0))


def test_speed_ladders_are_squares_for_mitsubas_stratified_sampler():
    for cfg in (suite.QUICK, suite.FULL):
        assert all(math.isqrt(n) ** 2 == n for n in cfg.ladder), cfg.ladder


def test_vector_isa_names_the_widest_extension():
    assert suite.vector_isa("flags\t\t: fpu sse2 avx avx2 fma avx512f avx512bw") == "AVX-512"
    assert suite.vector_isa("flags : fpu sse2 avx avx2 fma") == "AVX2"
    assert suite.vector_isa("flags : fpu sse sse2") == "SSE"
    assert suite.vector_isa() in {"AVX-512", "AVX2", "SSE"} or suite.vector_isa() == suite.platform.machine()
    assert "16 lanes" in suite.drjit_lanes_md(("znver5", 16))
    assert "no LLVM variant" in suite.drjit_lanes_md(None)


def test_bootstrap_counts_resample_every_round_with_replacement():
    counts = suite.bootstrap_counts(8, n_boot=50, seed=3)
    assert counts.shape == (50, 8)
    assert np.all(counts.sum(axis=1) == 8)
    assert np.any(counts.max(axis=1) > 1)           # some rounds drawn twice
    assert np.array_equal(counts, suite.bootstrap_counts(8, n_boot=50, seed=3))  # reproducible


def test_resampled_relmse_and_medians_match_the_resamples_taken_one_by_one():
    rng = np.random.default_rng(7)
    k, shape = 6, (8, 8, 3)
    ref = rng.uniform(0.1, 2.0, shape)
    runs = ref + 0.1 * rng.standard_normal((k,) + shape)
    times = rng.uniform(0.5, 1.5, k)
    counts = np.vstack([np.ones(k), suite.bootstrap_counts(k, n_boot=20, seed=1)])
    fast = suite.resampled_relmse(runs, ref, counts)
    med = suite.resampled_medians(times, counts)
    assert fast[0] == pytest.approx(suite.relmse_from_runs(runs, ref))
    for i, c in enumerate(counts):
        idx = np.repeat(np.arange(k), c.astype(int))
        assert fast[i] == pytest.approx(suite.relmse_from_runs(runs[idx], ref), rel=1e-9)
        assert med[i] == pytest.approx(np.median(times[idx]))


def _synthetic_ladder(rng, variance, spps, k, ms_per_sample, ref):
    """One renderer's rungs: K renders of noise variance `variance` / spp, timings with 5%
    jitter around spp x ms_per_sample, resampled by bootstrap_rung."""
    boot = []
    for spp in spps:
        imgs = ref + np.sqrt(variance / spp) * rng.standard_normal((k,) + ref.shape)
        times = spp * ms_per_sample * 1e-3 * (1 + 0.05 * rng.standard_normal(k))
        counts = suite.bootstrap_counts(k, seed=suite.BOOTSTRAP_SEED + spp)
        boot.append(suite.bootstrap_rung(imgs, times, ref, suite.to_blocks(ref), counts))
    return boot


@pytest.mark.parametrize("marginal", [False, True])
def test_ratio_interval_covers_the_true_ratio_and_collapses_for_identical_renderers(marginal):
    rng = np.random.default_rng(11)
    spps, k = [16, 64, 256], 8
    ref = rng.uniform(0.2, 1.0, (32, 32, 3))
    kauri = _synthetic_ladder(rng, 0.04, spps, k, 1.0, ref)
    # Twice kauri's variance at the same speed: the peer needs twice the time (ratio 2).
    peer = _synthetic_ladder(rng, 0.08, spps, k, 1.0, ref)
    for metric in ("pixel", "block"):
        lo, hi = suite.ratio_interval(peer, kauri, spps, metric, min_spp=16, marginal=marginal)
        assert lo < 2.0 < hi
        assert hi - lo < 1.0     # informative, not anything at all
        same = suite.ratio_interval(kauri, kauri, spps, metric, min_spp=16, marginal=marginal)
        assert same == pytest.approx((1.0, 1.0))


def test_fmt_ratio_prints_the_interval_when_there_is_one():
    assert suite.fmt_ratio(1.0789, (0.951, 1.214)) == "1.08 [0.951–1.21]"
    assert suite.fmt_ratio(1.0789, None) == "1.08"
    assert suite.fmt_ratio(None, (1.0, 2.0)) == "–"


def test_memory_deltas_below_zero_are_marked_as_noise():
    assert suite.fmt_mem_delta(5 * 1024) == "5"
    assert suite.fmt_mem_delta(-30 * 1024) == "-30*"


def _colour_noise_module():
    path = os.path.join(os.path.dirname(__file__), "..", "..", "bench", "colour_noise.py")
    spec = importlib.util.spec_from_file_location("bench_colour_noise", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_colour_noise_boxes_recolour_only_the_walls():
    cn = _colour_noise_module()
    bench = {s["name"]: s for s in cn.box("bench")["shapes"]}
    grey = {s["name"]: s for s in cn.box("grey")["shapes"]}
    sat = {s["name"]: s for s in cn.box("saturated")["shapes"]}
    assert bench["left"]["diffuse"] != bench["right"]["diffuse"]  # the suite's box, untouched
    for name, shape in grey.items():
        if "diffuse" in shape:
            assert shape["diffuse"] == cn.GREY
    assert sat["left"]["diffuse"] == (0.9, 0.1, 0.1) and sat["right"]["diffuse"] == (0.1, 0.9, 0.1)
    assert sat["floor"]["diffuse"] == cn.GREY
    # The lamp and the geometry stay the suite's in every version.
    for box in (grey, sat):
        assert box["light"] == bench["light"] and box["floor"]["quad"] == bench["floor"]["quad"]


def test_colour_noise_variance_is_the_spread_about_the_renders_own_mean():
    cn = _colour_noise_module()
    rng = np.random.default_rng(7)
    mean = rng.uniform(0.5, 1.5, (8, 8, 3))
    sigma = 0.1
    runs = [mean + sigma * rng.standard_normal(mean.shape) for _ in range(400)]
    expected = np.mean(sigma ** 2 / (mean ** 2 + suite.REL_EPS))
    assert cn.relative_variance(runs) == pytest.approx(expected, rel=0.03)
    assert cn.relative_variance([np.ones((2, 2, 3))] * 3) == 0.0
