"""kauri: a spectral production path tracer.

Build a scene with :class:`Scene`, materials (:class:`Lambert`, :class:`Dielectric`,
:class:`Conductor`), :class:`Emission`, lights and a camera; call :func:`render`.
"""
from . import _core
from .render import RenderOutput, render
from .scene import Conductor, Dielectric, Emission, Lambert, Material, Scene, SceneError

__version__ = _core.__version__
__all__ = ["Scene", "Lambert", "Dielectric", "Conductor", "Emission", "Material", "SceneError", "render",
           "RenderOutput", "__version__"]
