"""kauri.render(): render a Scene and get NumPy arrays back."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from .scene import Scene, SceneError

_RENDER_KEYS = ("spp", "resolution", "seed", "threads", "time_limit", "sampler", "max_depth", "max_diffuse",
                "max_glossy", "max_transmission", "clamp", "filter", "filter_radius", "filter_sigma", "progress")


@dataclass
class RenderOutput:
    """Beauty (RGBA, working space) and AOVs as float32 arrays, plus statistics."""
    rgba: np.ndarray
    albedo: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    stats: dict
    color_space: str
    _result: object

    def write_exr(self, path: str, scene_name: str = "") -> None:
        """Multi-channel EXR (R,G,B,A, albedo.*, N.*, Z) with metadata, written atomically."""
        self._result.write_exr(str(path), scene_name)

    def write_png(self, path: str, exposure: float = 0.0) -> None:
        """8-bit sRGB preview, written atomically."""
        self._result.write_png(str(path), float(exposure))


def render(scene: Scene, spp: int = 64, resolution=(640, 480), seed: int = 0, threads: int = 0,
           time_limit: float = 0.0, sampler: str = "sobol", max_depth: int = 16, max_diffuse: int = 6,
           max_glossy: int = 8, max_transmission: int = 12, clamp: float = 0.0, filter: str = "gaussian",
           filter_radius: float = 2.0, filter_sigma: float = 0.5, progress: bool = False,
           **extra) -> RenderOutput:
    """Renders ``scene``; returns a RenderOutput. Stops after ``spp`` samples per pixel or at
    the first pass boundary after ``time_limit`` seconds. Deterministic for a given seed,
    whatever ``threads`` is. The pixel filter is a Gaussian of std-dev ``filter_sigma``
    truncated at ``filter_radius`` pixels (0.5 / 2.0, Mitsuba's defaults), or a box."""
    if extra:
        raise SceneError(f"render: unknown parameter(s) {', '.join(map(repr, sorted(extra)))}; "
                         f"allowed: {', '.join(_RENDER_KEYS)}")
    if not isinstance(scene, Scene):
        raise SceneError(f"render: parameter 'scene': expected kauri.Scene, got {type(scene).__name__}")
    if not scene.has_camera:
        raise SceneError("render: the scene has no camera; call scene.set_camera()")
    try:
        w, h = (int(v) for v in resolution)
    except (TypeError, ValueError):
        raise SceneError(f"render: parameter 'resolution': expected (width, height), got {resolution!r}") from None
    for name, v in (("spp", spp), ("seed", seed), ("threads", threads)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            raise SceneError(f"render: parameter '{name}': expected an integer, got {type(v).__name__}")
    if seed < 0:
        raise SceneError("render: parameter 'seed': must be >= 0")
    r = _core.render(scene._core, w, h, int(spp), int(seed), int(threads), float(time_limit), sampler,
                     int(max_depth), int(max_diffuse), int(max_glossy), int(max_transmission), float(clamp),
                     filter, float(filter_radius), float(filter_sigma), bool(progress))
    return RenderOutput(r.rgba, r.albedo, r.normal, r.depth, r.stats, r.color_space, r)
