"""kauri: a spectral production path tracer.

Build a scene with :class:`Scene`, materials (:class:`Lambert`, :class:`Dielectric`,
:class:`Conductor`), :class:`Emission`, lights and a camera; call :func:`render`.
"""
from ._isa import load_core

# The widest compiled core this CPU runs (x86-64-v4 or x86-64-v3; KAURI_ISA overrides),
# registered as kauri._core before the modules below import it.
_core, _core_isa, _cores = load_core(__name__)
from .render import RenderOutput, ray_replay, render
from .scene import (Attribute, Conductor, Dielectric, DiffuseTransmission, Emission, EmissionLobe, ImageTexture, Lambert, Lobe,
                    Material, OrenNayar,
                    RoughDielectric, Scene, SceneError, Sheen, ThinDielectric)

__version__ = _core.__version__
#: How the native module was compiled: {"compiler", "march", "pgo", "cores"} (pgo: off,
#: generate or use; march: the target of the core this process loaded; cores: the cores the
#: build has, "base" and where built "x86-64-v4", of which import takes the widest the CPU
#: runs: python/kauri/_isa.py).
build_info = dict(_core.build_info, cores=_cores)
__all__ = ["Scene", "Lambert", "Dielectric", "Conductor", "Emission", "Material", "Lobe", "Attribute", "SceneError", "render",
           "RoughDielectric", "ThinDielectric", "DiffuseTransmission", "Sheen", "EmissionLobe", "OrenNayar", "ImageTexture",
           "RenderOutput", "ray_replay", "__version__", "build_info"]
