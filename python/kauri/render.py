"""kauri.render(): render a Scene and get NumPy arrays back."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from . import _core
from .scene import Scene, SceneError

_RENDER_KEYS = ("spp", "resolution", "seed", "threads", "time_limit", "sampler", "max_depth", "max_diffuse",
                "max_glossy", "max_transmission", "rr_depth", "clamp", "filter", "filter_radius", "filter_sigma", "reconstruction",
                "progress", "aovs", "light_sampler", "light_aa", "path_lanes")


@dataclass
class RenderOutput:
    """Beauty (RGBA, working space) and AOVs as float32 arrays, plus statistics. The AOVs
    are None when the render was asked not to compute them (``aovs=False``)."""
    rgba: np.ndarray
    albedo: Optional[np.ndarray]
    normal: Optional[np.ndarray]
    depth: Optional[np.ndarray]
    stats: dict
    color_space: str
    _result: object

    def write_exr(self, path: str, scene_name: str = "") -> None:
        """Multi-channel EXR (R,G,B,A, albedo.*, N.*, Z; RGBA alone without AOVs) with metadata,
        written atomically."""
        self._result.write_exr(str(path), scene_name)

    def write_png(self, path: str, exposure: float = 0.0) -> None:
        """8-bit sRGB preview, written atomically."""
        self._result.write_png(str(path), float(exposure))


def _check_integer(what: str, name: str, v) -> None:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise SceneError(f"{what}: parameter '{name}': expected an integer, got {type(v).__name__}")


def _check_render_args(what: str, scene, resolution, spp, seed, threads) -> tuple:
    if not isinstance(scene, Scene):
        raise SceneError(f"{what}: parameter 'scene': expected kauri.Scene, got {type(scene).__name__}")
    if not scene.has_camera:
        raise SceneError(f"{what}: the scene has no camera; call scene.set_camera()")
    try:
        w, h = (int(v) for v in resolution)
    except (TypeError, ValueError):
        raise SceneError(f"{what}: parameter 'resolution': expected (width, height), got {resolution!r}") from None
    for name, v in (("spp", spp), ("seed", seed), ("threads", threads)):
        _check_integer(what, name, v)
    if seed < 0:
        raise SceneError(f"{what}: parameter 'seed': must be >= 0")
    return w, h


def render(scene: Scene, spp: int = 64, resolution=(640, 480), seed: int = 0, threads: int = 0,
           time_limit: float = 0.0, sampler: str = "zsobol", max_depth: int = 16, max_diffuse: int = 6,
           max_glossy: int = 8, max_transmission: int = 12, clamp: float = 0.0, filter: str = "gaussian",
           filter_radius: float = 2.0, filter_sigma: float = 0.5, reconstruction: str = "splat",
           progress: bool = False, aovs: bool = True, light_sampler: str = "tree", rr_depth: int = 4,
           light_aa: int = 4, path_lanes: bool = True, **extra) -> RenderOutput:
    """Renders ``scene``; returns a RenderOutput. Stops after ``spp`` samples per pixel or at
    the first pass boundary after ``time_limit`` seconds. Deterministic for a given seed,
    whatever ``threads`` is. The pixel filter is a Gaussian of std-dev ``filter_sigma``
    truncated at ``filter_radius`` pixels (0.5 / 2.0, Mitsuba's defaults), or a box.
    ``reconstruction``: "splat" (default) adds each sample, weighted by the filter, to every
    pixel within the radius (lower per-pixel noise, correlated between neighbours);
    "filter_importance" draws the sample position from the filter and gives it to its own
    pixel alone (uncorrelated noise). Data AOVs always average a pixel's own samples.
    ``aovs=False`` renders the beauty alone (no albedo, normal or depth; the first hit's
    albedo is a quadrature for metals, so this is a few percent faster): the image is
    bit-identical to the one with AOVs. ``light_sampler``: how next-event estimation picks
    a light: "tree" (default) chooses among area and point lights by a light tree, in
    proportion to a bound on what each contributes at the shading point (many-light
    scenes); "power" in proportion to power alone. Environment and distant lights keep
    their power share either way. ``sampler``: "zsobol" (default) Owen-scrambled Sobol'
    points with neighbouring pixels taking blocks of one sequence in a scrambled Morton
    order (blue-noise error, as pbrt-v4's ZSobol); "sobol", the same points with each pixel
    scrambled on its own; "independent", PCG32 streams. ``rr_depth``: diffuse bounces a path
    makes before Russian roulette may end it (default 4; glossy and specular bounces do not
    count; a value above ``max_diffuse`` turns roulette off, and the bounce budgets alone end
    paths). Roulette is unbiased: it changes noise and speed, not the expected image.
    ``light_aa``: light antialiasing, extra camera rays per sample (default 4, 0: off) in the
    pixels where a probe finds the edge of a light seen directly (a small lamp, a
    silhouette against a constant sky); they gather only that light's colour, which the
    sample's path then leaves to them. The same image in the limit (each extra ray is
    distributed as the sample's own position): it lowers the coverage noise of bright
    lights seen by the camera at a camera ray's cost instead of a path's (render/light_aa.h)."""
    if extra:
        raise SceneError(f"render: unknown parameter(s) {', '.join(map(repr, sorted(extra)))}; "
                         f"allowed: {', '.join(_RENDER_KEYS)}")
    w, h = _check_render_args("render", scene, resolution, spp, seed, threads)
    _check_integer("render", "rr_depth", rr_depth)
    if rr_depth < 0:
        raise SceneError(f"render: parameter 'rr_depth': must be >= 0, got {rr_depth}")
    _check_light_aa("render", light_aa)
    r = _core.render(scene._core, w, h, int(spp), int(seed), int(threads), float(time_limit), sampler,
                     int(max_depth), int(max_diffuse), int(max_glossy), int(max_transmission), float(clamp),
                     filter, float(filter_radius), float(filter_sigma), reconstruction, bool(progress), bool(aovs),
                     light_sampler, int(rr_depth), int(light_aa), bool(path_lanes))
    return RenderOutput(r.rgba, r.albedo, r.normal, r.depth, r.stats, r.color_space, r)


def _check_light_aa(where: str, light_aa) -> None:
    _check_integer(where, "light_aa", light_aa)
    if not 0 <= light_aa <= 64:
        raise SceneError(f"{where}: parameter 'light_aa': must be in [0, 64] (extra camera rays per sample), "
                         f"got {light_aa}")


def ray_replay(scene: Scene, spp: int = 16, resolution=(128, 128), seed: int = 0, threads: int = 0,
               sampler: str = "zsobol", max_depth: int = 16, max_diffuse: int = 6, max_glossy: int = 8,
               max_transmission: int = 12, filter: str = "gaussian", filter_radius: float = 2.0,
               filter_sigma: float = 0.5, reconstruction: str = "splat", max_rays: int = 50_000_000,
               repeats: int = 3, aovs: bool = True, light_aa: int = 4, packets=()) -> dict:
    """Closeness to the limit: traces ``scene``'s paths on one thread recording every ray
    query, then ``repeats`` times renders it as render() would (multi-threaded, timed) and
    replays the recorded rays through the accelerator alone (Embree's rtcIntersect1 /
    rtcOccluded1 and the direct tests of a root group's few spheres and disks, ``threads``
    threads; every query alone, although the render traces each pixel's camera rays as
    packets of 8), alternately, and keeps the best time of each. Returns the counts and
    times, plus ``render_rays_per_second``, ``embree_rays_per_second`` and their ratio
    ``fraction_of_embree`` (1 = the path tracer costs nothing beyond traversal).
    ``hits_match`` checks the replay found the same hits.
    ``aovs`` and ``light_aa`` as in render() (the extra camera rays are recorded and
    replayed like every other ray).
    ``packets``: widths (8, 16) at which the same rays are also replayed as Embree packets
    of incoherent rays (rtcIntersect8/16, rtcOccluded8/16; the recorded order, a packet at
    a time), in the same alternation: what traversal would cost an integrator that traces
    a packet of paths at once. ``packet_replay[w]`` has their ``embree_rays_per_second``,
    its ratio to the single-ray replay's (``speedup_over_single``) and ``hits_match``."""
    w, h = _check_render_args("ray_replay", scene, resolution, spp, seed, threads)
    _check_light_aa("ray_replay", light_aa)
    try:
        widths = [int(x) for x in packets]
    except (TypeError, ValueError):
        raise ValueError(f"ray_replay: parameter 'packets': expected a sequence of packet widths (8, 16), got {packets!r}") from None
    if any(x not in (8, 16) for x in widths):
        raise ValueError(f"ray_replay: parameter 'packets': widths must be 8 or 16, got {widths}")
    d = dict(_core.ray_replay(scene._core, w, h, int(spp), int(seed), int(threads), sampler, int(max_depth),
                              int(max_diffuse), int(max_glossy), int(max_transmission), filter, float(filter_radius),
                              float(filter_sigma), reconstruction, int(max_rays), int(repeats), bool(aovs),
                              int(light_aa), widths))
    d["render_rays_per_second"] = d["render_rays"] / d["render_seconds"] if d["render_seconds"] > 0 else 0.0
    t = d["replay_closest_seconds"] + d["replay_shadow_seconds"]
    d["embree_rays_per_second"] = (d["closest_rays"] + d["shadow_rays"]) / t if t > 0 else 0.0
    d["fraction_of_embree"] = (d["render_rays_per_second"] / d["embree_rays_per_second"]
                               if d["embree_rays_per_second"] > 0 else 0.0)
    d["hits_match"] = (d["recorded_closest_hits"] == d["replay_closest_hits"] and
                       d["recorded_shadow_hits"] == d["replay_shadow_hits"])
    n = d["closest_rays"] + d["shadow_rays"]
    d["packet_replay"] = {}
    for width, p in d.pop("packets").items():
        tp = p["closest_seconds"] + p["shadow_seconds"]
        rps = n / tp if tp > 0 else 0.0
        d["packet_replay"][int(width)] = {
            "closest_seconds": p["closest_seconds"], "shadow_seconds": p["shadow_seconds"],
            "embree_rays_per_second": rps,
            "speedup_over_single": rps / d["embree_rays_per_second"] if d["embree_rays_per_second"] > 0 else 0.0,
            "hits_match": (p["closest_hits"] == d["recorded_closest_hits"] and
                           p["shadow_hits"] == d["recorded_shadow_hits"])}
    return d
