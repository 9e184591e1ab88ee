"""kauri: a spectral production path tracer.

Build a scene with :class:`Scene`, materials (:class:`Lambert`, :class:`Dielectric`,
:class:`Conductor`), :class:`Emission`, lights and a camera; call :func:`render`.
"""
from . import _core
from .render import RenderOutput, ray_replay, render
from .scene import (Attribute, Conductor, Dielectric, DiffuseTransmission, Emission, EmissionLobe, ImageTexture, Lambert, Lobe,
                    Material, OrenNayar,
                    RoughDielectric, Scene, SceneError, Sheen, ThinDielectric)

__version__ = _core.__version__
#: How the native module was compiled: {"compiler", "march", "pgo"} (pgo: off, generate or use).
build_info = dict(_core.build_info)
__all__ = ["Scene", "Lambert", "Dielectric", "Conductor", "Emission", "Material", "Lobe", "Attribute", "SceneError", "render",
           "RoughDielectric", "ThinDielectric", "DiffuseTransmission", "Sheen", "EmissionLobe", "OrenNayar", "ImageTexture",
           "RenderOutput", "ray_replay", "__version__", "build_info"]
