"""Building scenes in Python: materials, shapes, lights and cameras.

Every constructor checks its keyword arguments: an unknown parameter, a wrong
type or an out-of-range value raises an exception that names the object and the
parameter, before anything reaches the renderer.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from . import _core


class SceneError(ValueError):
    """Invalid scene input (names the object and parameter)."""


def _vec3(obj: str, param: str, value) -> tuple:
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise SceneError(f"{obj}: parameter '{param}': expected 3 numbers, got {value!r}") from None
    if arr.size == 1:
        arr = np.repeat(arr, 3)
    if arr.size != 3:
        raise SceneError(f"{obj}: parameter '{param}': expected 3 numbers, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"{obj}: parameter '{param}': must be finite, got {value!r}")
    return tuple(float(x) for x in arr)


def _number(obj: str, param: str, value, lo=-math.inf, hi=math.inf) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SceneError(f"{obj}: parameter '{param}': expected a number, got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v) or v < lo or v > hi:
        raise SceneError(f"{obj}: parameter '{param}': must be finite and in [{lo}, {hi}], got {value!r}")
    return v


def _unit_rgb(obj: str, param: str, value) -> tuple:
    """An RGB triple with every component in [0, 1] (reflectances, transmittances)."""
    c = _vec3(obj, param, value)
    if min(c) < 0 or max(c) > 1:
        raise SceneError(f"{obj}: parameter '{param}': components must lie in [0, 1], got {c}")
    return c


class ImageTexture:
    """An image texture for a lobe's colour: Lambert / OrenNayar ``albedo``,
    DiffuseTransmission ``transmittance``, Sheen ``color``.

    ``image``: an (height, width, 3) array of linear RGB in the scene's working space, or an
    image file path read through OpenImageIO (8-bit PNG/JPEG are decoded from sRGB to
    linear; EXR is taken as linear). Lookups are bilinear, (u, v) = (0, 0) is the
    bottom-left corner of the image (OpenGL / USD convention); ``wrap`` is 'repeat' or
    'clamp'. No mip-mapping yet."""

    def __init__(self, image, wrap: str = "repeat", name: str = "texture"):
        obj = f"texture '{name}'"
        if isinstance(image, (str, os.PathLike)):
            try:
                image = _core.read_rgb_image(os.fspath(image))
            except ValueError as e:
                raise SceneError(f"{obj}: {e}") from None
        a = np.asarray(image, dtype=np.float32)
        if a.ndim != 3 or a.shape[2] not in (3, 4) or a.shape[0] == 0 or a.shape[1] == 0:
            raise SceneError(f"{obj}: parameter 'image': expected an (height, width, 3) array, got shape {a.shape}")
        a = np.ascontiguousarray(a[:, :, :3])
        if not np.all(np.isfinite(a)) or a.min() < 0:
            raise SceneError(f"{obj}: parameter 'image': texels must be finite and >= 0")
        if wrap not in ("repeat", "clamp"):
            raise SceneError(f"{obj}: parameter 'wrap': expected 'repeat' or 'clamp', got {wrap!r}")
        self.name, self.image, self.wrap = name, a, wrap


def _color_input(obj: str, param: str, value):
    """A reflectance-like colour: an RGB triple in [0, 1] or an ImageTexture whose texels
    lie in [0, 1] (a reflectance above 1 would create energy)."""
    if isinstance(value, ImageTexture):
        peak = float(value.image.max())
        if peak > 1:
            raise SceneError(f"{obj}: parameter '{param}': texture '{value.name}' has texels up to {peak:.4g}; "
                             "a reflectance texture must lie in [0, 1]")
        return value
    if isinstance(value, dict) and "texture" in value:  # material files: {"texture": path, "wrap": ...}
        _check_keys(f"{obj}: parameter '{param}'", value, ["texture", "wrap"])
        return _color_input(obj, param, ImageTexture(value["texture"], value.get("wrap", "repeat"),
                                                     name=os.path.basename(str(value["texture"]))))
    return _unit_rgb(obj, param, value)


def _check_keys(obj: str, given: dict, allowed: Sequence[str]) -> None:
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        raise SceneError(f"{obj}: unknown parameter(s) {', '.join(repr(u) for u in unknown)}; "
                         f"allowed: {', '.join(allowed)}")


# ---------------------------------------------------------------- lobes and materials

class Attribute:
    """A per-vertex input: the mesh attribute ``name`` (given to add_mesh(attributes=...)),
    times ``scale``. Usable wherever a weight is expected."""

    def __init__(self, name: str, scale: float = 1.0):
        if not isinstance(name, str) or not name:
            raise SceneError(f"Attribute: expected a non-empty name, got {name!r}")
        self.name = name
        self.scale = _number(f"attribute '{name}'", "scale", scale, 0)


def _weight(obj: str, param: str, value) -> dict:
    if isinstance(value, Attribute):
        return {"weight": value.scale, "weight_attribute": value.name}
    return {"weight": _number(obj, param, value, 0, 1)}


class Lobe:
    """A BSDF lobe description. A lobe used where a material is expected is a
    single-lobe material."""
    kind = ""

    def __init__(self, name: str, **params):
        self.name = name or self.kind
        self.params = params

    def to_dict(self, name: str, weight) -> dict:
        return {"name": name, "type": self.kind, **self.params,
                **_weight(f"lobe '{name}'", "weight", weight)}


class Lambert(Lobe):
    """Lambertian diffuse reflector (``lambert@1``). ``albedo``: RGB in the working space, in [0, 1]."""
    kind = "lambert"

    def __init__(self, albedo=(0.8, 0.8, 0.8), name: str = "", **extra):
        _check_keys(f"material '{name or self.kind}'", extra, ["albedo", "name"])
        obj = f"material '{name or self.kind}'"
        a = _color_input(obj, "albedo", albedo)
        super().__init__(name, albedo=a)


class OrenNayar(Lobe):
    """Energy-preserving rough diffuse (``oren_nayar@1``, EON: Fujii's Oren–Nayar form plus
    an exact multiple-scattering term): ``roughness`` 0 is Lambert; a white lobe reflects 1."""
    kind = "oren_nayar"

    def __init__(self, albedo=(0.8, 0.8, 0.8), roughness: float = 0.5, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["albedo", "roughness", "name"])
        a = _color_input(obj, "albedo", albedo)
        super().__init__(name, albedo=a, roughness=_number(obj, "roughness", roughness, 0, 1))


class Dielectric(Lobe):
    """Smooth dielectric (``smooth_dielectric@1``): glass, water.

    ``ior`` at 587.6 nm; ``abbe`` > 0 adds dispersion (Cauchy fit; e.g. 64 for BK7).
    """
    kind = "dielectric"

    def __init__(self, ior: float = 1.5, abbe: float = 0.0, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["ior", "abbe", "name"])
        super().__init__(name, ior=_number(obj, "ior", ior, 1.0 / 4, 4),
                         abbe=_number(obj, "abbe", abbe, 0, 1000))


class Conductor(Lobe):
    """Rough microfacet conductor with a spectral complex IOR (``ggx_conductor@2``: GGX with
    Kulla–Conty multiple-scattering compensation; ``compensate=False`` gives ``@1``).

    Give ``metal`` (measured data: Au, Ag, Cu, Al, Cr), or RGB ``eta`` and ``k``, or the artist
    parameters ``reflectivity`` and ``edge_tint`` (Gulbrandsen 2014). ``roughness`` in [0, 1]
    (α = roughness²), ``anisotropy`` in [-1, 1], ``microfacet`` "ggx" or "beckmann".
    """
    kind = "conductor"

    def __init__(self, metal: str = "Au", roughness: float = 0.3, anisotropy: float = 0.0,
                 eta=None, k=None, reflectivity=None, edge_tint=None, microfacet: str = "ggx",
                 compensate: bool = True, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["metal", "roughness", "anisotropy", "eta", "k", "reflectivity", "edge_tint",
                                 "microfacet", "compensate", "name"])
        if microfacet not in ("ggx", "beckmann"):
            raise SceneError(f"{obj}: parameter 'microfacet': expected 'ggx' or 'beckmann', got {microfacet!r}")
        refl = tint = None
        if reflectivity is not None or edge_tint is not None:
            refl = _vec3(obj, "reflectivity", 0.9 if reflectivity is None else reflectivity)
            tint = _vec3(obj, "edge_tint", 0.9 if edge_tint is None else edge_tint)
            if min(refl) < 0 or max(refl) > 0.999 or min(tint) < 0 or max(tint) > 1:
                raise SceneError(f"{obj}: parameters 'reflectivity' (< 1) and 'edge_tint' must lie in [0, 1]")
            metal, eta, k = "", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)
        elif eta is not None or k is not None:
            if eta is None or k is None:
                raise SceneError(f"{obj}: parameters 'eta' and 'k' must be given together")
            metal = ""
            eta, k = _vec3(obj, "eta", eta), _vec3(obj, "k", k)
        else:
            if not isinstance(metal, str):
                raise SceneError(f"{obj}: parameter 'metal': expected a name, got {type(metal).__name__}")
            eta, k = (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)
        super().__init__(name, metal=metal, eta=eta, k=k, reflectivity=refl, edge_tint=tint,
                         microfacet=microfacet, compensate=bool(compensate),
                         roughness=_number(obj, "roughness", roughness, 0, 1),
                         anisotropy=_number(obj, "anisotropy", anisotropy, -1, 1))


class RoughDielectric(Lobe):
    """Rough GGX dielectric (``ggx_dielectric@2``: with multiple-scattering compensation from
    our own albedo tables): frosted glass, rough water; reflection and refraction. ``ior`` at
    587.6 nm, ``abbe`` for dispersion, ``roughness``, ``anisotropy``."""
    kind = "rough_dielectric"

    def __init__(self, ior: float = 1.5, roughness: float = 0.2, anisotropy: float = 0.0, abbe: float = 0.0,
                 compensate: bool = True, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["ior", "roughness", "anisotropy", "abbe", "compensate", "name"])
        super().__init__(name, ior=_number(obj, "ior", ior, 1.0 / 4, 4), abbe=_number(obj, "abbe", abbe, 0, 1000),
                         compensate=bool(compensate),
                         roughness=_number(obj, "roughness", roughness, 0, 1),
                         anisotropy=_number(obj, "anisotropy", anisotropy, -1, 1))


class ThinDielectric(Lobe):
    """A thin glass sheet (``thin_dielectric@1``): mirror reflection with the sheet's internal
    bounces, straight-through transmission. For windows and bubbles modelled as one surface."""
    kind = "thin_dielectric"

    def __init__(self, ior: float = 1.5, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["ior", "name"])
        super().__init__(name, ior=_number(obj, "ior", ior, 1.0 / 4, 4), abbe=0.0)


class DiffuseTransmission(Lobe):
    """Tinted Lambertian transmission (``diffuse_transmission@1``): leaves, paper, lampshades."""
    kind = "diffuse_transmission"

    def __init__(self, transmittance=(0.5, 0.5, 0.5), name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["transmittance", "name"])
        t = _color_input(obj, "transmittance", transmittance)
        super().__init__(name, transmittance=t)


class Sheen(Lobe):
    """Fabric sheen (``sheen@1``, Estevez–Kulla "Charlie" distribution): velvet, cloth, dust."""
    kind = "sheen"

    def __init__(self, color=(1.0, 1.0, 1.0), roughness: float = 0.4, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["color", "roughness", "name"])
        c = _color_input(obj, "color", color)
        super().__init__(name, color=c, roughness=_number(obj, "roughness", roughness, 0, 1))


class EmissionLobe(Lobe):
    """An emission node (EDF) for layered materials: diffuse (``focus=0``) or focused as
    cos^focus (peak scaled so the exitance matches the diffuse EDF). Radiance from RGB
    ``color`` (working space), a blackbody ``temperature`` (K, luminance 1) or a tabulated
    ``spectrum`` [(nm, value), ...], times ``intensity``. Combine emission nodes with
    ``add``; coat them under a varnish to dim them. Shapes with an emissive material are
    lights. Weights in an emissive material must be constants."""
    kind = "emission"

    def __init__(self, color=(1.0, 1.0, 1.0), intensity: float = 1.0, temperature: float = 0.0, spectrum=None,
                 focus: float = 0.0, two_sided: bool = False, name: str = "", **extra):
        obj = f"material '{name or self.kind}'"
        _check_keys(obj, extra, ["color", "intensity", "temperature", "spectrum", "focus", "two_sided", "name"])
        c = _vec3(obj, "color", color)
        if min(c) < 0:
            raise SceneError(f"{obj}: parameter 'color': components must be >= 0")
        spec = None
        if spectrum is not None:
            try:
                arr = np.asarray(spectrum, dtype=np.float64)
            except (TypeError, ValueError):
                raise SceneError(f"{obj}: parameter 'spectrum': expected [(nm, value), ...]") from None
            if arr.ndim != 2 or arr.shape[1] != 2:
                raise SceneError(f"{obj}: parameter 'spectrum': expected an (n, 2) list of (nm, value)")
            spec = [(float(a), float(b)) for a, b in arr]
        super().__init__(name, color=c, intensity=_number(obj, "intensity", intensity, 0),
                         temperature=_number(obj, "temperature", temperature, 0), spectrum=spec,
                         focus=_number(obj, "focus", focus, 0, 1000), two_sided=bool(two_sided))


LOBE_TYPES = {"lambert": Lambert, "oren_nayar": OrenNayar, "dielectric": Dielectric, "conductor": Conductor,
              "rough_dielectric": RoughDielectric, "thin_dielectric": ThinDielectric,
              "diffuse_transmission": DiffuseTransmission, "sheen": Sheen, "emission": EmissionLobe}
OPERATORS = ("mix", "coat", "blend", "add")


class Material:
    """A layered material (Manuka-style, course notes §8.4): named lobes combined by
    operators into a tree. Reads like the notes' shader code::

        paint = kauri.Material("car_paint")
        paint.add_lobe("flakes", kauri.Conductor(metal="Al", roughness=0.4))
        paint.add_lobe("clear", kauri.Dielectric(ior=1.5))
        paint.combine("paint", "coat", "clear", "flakes")

    ``coat`` puts its first input on top of the second; ``mix`` normalises the weights of
    2–8 inputs; ``blend`` substitutes the second input where the first is absent; ``add``
    is for emission and becomes ``coat`` (with a warning) on scattering lobes.
    ``symmetric=False`` makes the stack single-sided: seen from behind, it is evaluated
    in inverse order. ``ior_accumulation`` / ``roughness_accumulation`` make lobes under
    a layer see its IOR and be at least as rough as it.
    """

    def __init__(self, name: str = "material", symmetric: bool = True, ior_accumulation: bool = False,
                 roughness_accumulation: bool = False, root: str = "", **extra):
        _check_keys(f"material '{name}'", extra, [])
        self.name = name
        self.symmetric = bool(symmetric)
        self.ior_accumulation = bool(ior_accumulation)
        self.roughness_accumulation = bool(roughness_accumulation)
        self.root = root
        self.lobes: list[dict] = []
        self.layers: list[dict] = []
        self._names: set[str] = set()

    def _new_name(self, name: str) -> str:
        if not isinstance(name, str) or not name:
            raise SceneError(f"material '{self.name}': node names must be non-empty strings, got {name!r}")
        if name in self._names:
            raise SceneError(f"material '{self.name}', node '{name}': duplicate node name")
        self._names.add(name)
        return name

    def add_lobe(self, name: str, lobe: Lobe, weight=1.0) -> "Material":
        """Adds lobe ``lobe`` as node ``name`` with weight w_b (a number in [0, 1] or an Attribute)."""
        if not isinstance(lobe, Lobe):
            raise SceneError(f"material '{self.name}', node '{name}': expected a lobe "
                             f"({', '.join(c.__name__ for c in LOBE_TYPES.values())}), got {type(lobe).__name__}")
        obj = f"material '{self.name}', node '{name}'"
        w = _weight(obj, "weight", weight)
        self._new_name(name)
        self.lobes.append({"name": name, "type": lobe.kind, **lobe.params, **w})
        return self

    def combine(self, name: str, op: str, *inputs: str, weight=1.0) -> "Material":
        """Adds operator node ``name`` = op(inputs...) with layer weight w_l."""
        obj = f"material '{self.name}', node '{name}'"
        if op not in OPERATORS:
            raise SceneError(f"{obj}: unknown operator {op!r}; expected one of {', '.join(OPERATORS)}")
        for i in inputs:
            if not isinstance(i, str):
                raise SceneError(f"{obj}: inputs are node names, got {type(i).__name__}")
        w = _weight(obj, "weight", weight)
        self._new_name(name)
        self.layers.append({"name": name, "op": op, "inputs": list(inputs), **w})
        return self

    @classmethod
    def from_dict(cls, data: dict, source: str = "<dict>") -> "Material":
        """Builds a material from the plain-data form used by material files (see docs/materials.md)."""
        where = f"{source}: material"
        if not isinstance(data, dict):
            raise SceneError(f"{where}: expected an object, got {type(data).__name__}")
        _check_keys(where, data, ["name", "symmetric", "ior_accumulation", "roughness_accumulation", "root",
                                  "lobes", "layers"])
        m = cls(name=data.get("name", "material"), symmetric=data.get("symmetric", True),
                ior_accumulation=data.get("ior_accumulation", False),
                roughness_accumulation=data.get("roughness_accumulation", False), root=data.get("root", ""))
        for i, spec in enumerate(data.get("lobes", [])):
            if not isinstance(spec, dict):
                raise SceneError(f"{source}: material '{m.name}': lobes[{i}]: expected an object")
            spec = dict(spec)
            name, kind = spec.pop("name", None), spec.pop("type", None)
            if kind not in LOBE_TYPES:
                raise SceneError(f"{source}: material '{m.name}', node '{name}': unknown lobe type {kind!r}; "
                                 f"expected one of {', '.join(LOBE_TYPES)}")
            weight = _parse_weight(spec.pop("weight", 1.0))
            base = os.path.dirname(source) if os.path.isfile(source) else ""
            for key, value in spec.items():  # texture paths are relative to the material file
                if isinstance(value, dict) and isinstance(value.get("texture"), str):
                    spec[key] = {**value, "texture": os.path.join(base, value["texture"])}
            try:
                lobe = LOBE_TYPES[kind](**spec)
            except SceneError as e:
                raise SceneError(f"{source}: material '{m.name}', node '{name}': {e}") from None
            except TypeError as e:
                raise SceneError(f"{source}: material '{m.name}', node '{name}': {e}") from None
            m.add_lobe(name, lobe, weight)
        for i, spec in enumerate(data.get("layers", [])):
            if not isinstance(spec, dict):
                raise SceneError(f"{source}: material '{m.name}': layers[{i}]: expected an object")
            _check_keys(f"{source}: material '{m.name}', layers[{i}]", spec, ["name", "op", "inputs", "weight"])
            m.combine(spec.get("name"), spec.get("op"), *spec.get("inputs", []),
                      weight=_parse_weight(spec.get("weight", 1.0)))
        return m

    @classmethod
    def load(cls, path: str) -> list:
        """Reads a material file (JSON): one material object or {"materials": [...]}."""
        import json
        try:
            with open(path) as f:
                data = json.load(f)
        except json.JSONDecodeError as e:
            raise SceneError(f"{path}:{e.lineno}:{e.colno}: invalid JSON: {e.msg}") from None
        except OSError as e:
            raise SceneError(f"{path}: cannot read: {e.strerror}") from None
        items = data.get("materials", [data]) if isinstance(data, dict) else data
        return [cls.from_dict(d, path) for d in items]


def _parse_weight(w):
    """Material-file weights: a number, or {"attribute": name, "scale": s}."""
    if isinstance(w, dict):
        return Attribute(w.get("attribute", ""), w.get("scale", 1.0))
    return w


@dataclass
class Emission:
    """Diffuse emission: RGB ``color`` (working space) or blackbody ``temperature`` (K,
    normalised to luminance 1), times ``intensity``. One-sided unless ``two_sided``."""
    color: tuple = (1.0, 1.0, 1.0)
    intensity: float = 1.0
    temperature: float = 0.0
    two_sided: bool = False

    def resolved(self, obj: str) -> tuple:
        c = _vec3(obj, "emission.color", self.color)
        if min(c) < 0:
            raise SceneError(f"{obj}: parameter 'emission.color': components must be >= 0")
        return (c, _number(obj, "emission.intensity", self.intensity, 0),
                _number(obj, "emission.temperature", self.temperature, 0), bool(self.two_sided))


# ---------------------------------------------------------------- scene

_NO_EMISSION = ((1.0, 1.0, 1.0), 0.0, 0.0, False)


class Scene:
    """A scene built in code. Coordinates are right-handed with +Y up.

    >>> s = Scene()
    >>> red = Lambert(albedo=(0.7, 0.1, 0.1))
    >>> s.add_sphere(center=(0, 1, 0), radius=1, material=red)
    >>> s.add_environment(color=(1, 1, 1))
    >>> s.set_camera(eye=(0, 1, 5), target=(0, 1, 0), fov=40)
    """

    def __init__(self, color_space: str = "acescg"):
        self._core = _core.Scene()
        self._materials: dict[int, int] = {}
        self._material_objs: list[Material] = []
        self.color_space = color_space
        self._core.set_color_space(color_space)
        self._groups: dict[str, int] = {}
        self._textures: dict[int, int] = {}
        self._texture_objs: list[ImageTexture] = []
        self.has_camera = False

    # -- materials
    def _material_id(self, obj: str, material) -> int:
        if material is None:
            return -1
        if isinstance(material, Lobe):
            key = id(material)
            if key not in self._materials:
                m = Material(name=material.name)
                m.add_lobe(material.name, material)
                self._materials[key] = self._register(m)
                self._material_objs.append(material)  # keep alive so id() stays unique
            return self._materials[key]
        if isinstance(material, Material):
            key = id(material)
            if key not in self._materials:
                self._materials[key] = self._register(material)
                self._material_objs.append(material)
            return self._materials[key]
        raise SceneError(f"{obj}: parameter 'material': expected a kauri material or lobe "
                         f"(Material, Lambert, Dielectric, Conductor), got {type(material).__name__}")

    def _texture_lobe(self, lobe: dict) -> dict:
        """A lobe dict with ImageTexture colours replaced by scene texture ids."""
        for key, value in lobe.items():
            if isinstance(value, ImageTexture):
                tid = self._textures.get(id(value))
                if tid is None:
                    tid = self._core.add_texture(value.name, value.image, value.wrap)
                    self._textures[id(value)] = tid
                    self._texture_objs.append(value)  # keep alive so id() stays unique
                return {**lobe, key: (0.0, 0.0, 0.0), "texture": tid}
        return lobe

    def _register(self, m: Material) -> int:
        import warnings
        before = len(self._core.warnings())
        lobes = [self._texture_lobe(lobe) for lobe in m.lobes]
        mid = self._core.add_material(m.name, lobes, m.layers, m.root, m.symmetric, m.ior_accumulation,
                                      m.roughness_accumulation)
        for w in self._core.warnings()[before:]:
            warnings.warn(w, stacklevel=3)
        return mid

    def _group_id(self, obj: str, group: Optional[str]) -> int:
        if group is None:
            return 0
        if group not in self._groups:
            raise SceneError(f"{obj}: parameter 'group': unknown group {group!r}; create it with add_group()")
        return self._groups[group]

    @staticmethod
    def _emission(obj: str, emission) -> tuple:
        if emission is None:
            return (False,) + _NO_EMISSION
        if not isinstance(emission, Emission):
            raise SceneError(f"{obj}: parameter 'emission': expected kauri.Emission, got {type(emission).__name__}")
        return (True,) + emission.resolved(obj)

    # -- geometry
    def add_mesh(self, positions, indices, normals=None, uvs=None, material=None,
                 emission: Optional[Emission] = None, name: str = "mesh", group: Optional[str] = None,
                 attributes: Optional[dict] = None, **extra):
        """Triangle or quad mesh from NumPy arrays: positions (n, 3), indices (m, 3) or (m, 4),
        optional per-vertex normals (n, 3), uvs (n, 2) and named float ``attributes`` (n,)
        that material weights can read through kauri.Attribute."""
        obj = f"mesh '{name}'"
        _check_keys(obj, extra, [])
        P = np.ascontiguousarray(positions, dtype=np.float32)
        if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
            raise SceneError(f"{obj}: parameter 'positions': expected an (n, 3) array, got shape {P.shape}")
        I = np.asarray(indices)
        if I.ndim != 2 or I.shape[1] not in (3, 4) or I.shape[0] == 0:
            raise SceneError(f"{obj}: parameter 'indices': expected an (m, 3) or (m, 4) array, got shape {I.shape}")
        if not np.issubdtype(I.dtype, np.integer):
            raise SceneError(f"{obj}: parameter 'indices': expected integers, got {I.dtype}")
        if I.min() < 0 or I.max() >= P.shape[0]:
            bad = int(I.min()) if I.min() < 0 else int(I.max())
            raise SceneError(f"{obj}: parameter 'indices': index {bad} is out of range "
                             f"(the mesh has {P.shape[0]} vertices)")
        N = None if normals is None else np.ascontiguousarray(normals, dtype=np.float32)
        if N is not None and N.shape != P.shape:
            raise SceneError(f"{obj}: parameter 'normals': expected shape {P.shape}, got {N.shape}")
        UV = None if uvs is None else np.ascontiguousarray(uvs, dtype=np.float32)
        if UV is not None and UV.shape != (P.shape[0], 2):
            raise SceneError(f"{obj}: parameter 'uvs': expected shape {(P.shape[0], 2)}, got {UV.shape}")
        attrs = {}
        for key, values in (attributes or {}).items():
            A = np.ascontiguousarray(values, dtype=np.float32)
            if A.shape != (P.shape[0],):
                raise SceneError(f"{obj}: parameter 'attributes': {key!r} must have shape ({P.shape[0]},), got {A.shape}")
            attrs[str(key)] = A
        mid = self._material_id(obj, material)
        em = self._emission(obj, emission)
        return self._core.add_mesh(self._group_id(obj, group), name, P, np.ascontiguousarray(I, dtype=np.uint32),
                                   I.shape[1], N, UV, attrs, mid, *em)

    def add_sphere(self, center=(0, 0, 0), radius: float = 1.0, material=None,
                   emission: Optional[Emission] = None, name: str = "sphere", group: Optional[str] = None, **extra):
        obj = f"sphere '{name}'"
        _check_keys(obj, extra, [])
        return self._core.add_sphere(self._group_id(obj, group), name, _vec3(obj, "center", center),
                                     _number(obj, "radius", radius), self._material_id(obj, material),
                                     *self._emission(obj, emission))

    def add_disk(self, center=(0, 0, 0), normal=(0, 1, 0), radius: float = 1.0, material=None,
                 emission: Optional[Emission] = None, name: str = "disk", group: Optional[str] = None, **extra):
        obj = f"disk '{name}'"
        _check_keys(obj, extra, [])
        return self._core.add_disk(self._group_id(obj, group), name, _vec3(obj, "center", center),
                                   _vec3(obj, "normal", normal), _number(obj, "radius", radius),
                                   self._material_id(obj, material), *self._emission(obj, emission))

    def add_group(self, name: str) -> str:
        """A prototype for instancing: add shapes with ``group=name``, place it with add_instance()."""
        if name in self._groups:
            raise SceneError(f"group '{name}': a group of that name exists already")
        self._groups[name] = self._core.add_group(name)
        return name

    def add_instance(self, group: str, transform, name: str = "instance", **extra):
        """Places a group with a 3x4 or 4x4 object-to-world matrix."""
        obj = f"instance '{name}'"
        _check_keys(obj, extra, [])
        if group not in self._groups:
            raise SceneError(f"{obj}: parameter 'group': unknown group {group!r}")
        M = np.ascontiguousarray(transform, dtype=np.float32)
        return self._core.add_instance(name, self._groups[group], M)

    # -- lights
    def _light(self, kind, name, position=(0, 0, 0), direction=(0, -1, 0), color=(1, 1, 1), intensity=1.0,
               temperature=0.0, cone_angle=30.0, cone_softness=5.0, angle=0.0, image=None, rotation=None):
        obj = f"light '{name}'"
        c = _vec3(obj, "color", color)
        if min(c) < 0:
            raise SceneError(f"{obj}: parameter 'color': components must be >= 0")
        if image is not None:
            image = np.ascontiguousarray(image, dtype=np.float32)
            if image.ndim != 3 or image.shape[2] < 3:
                raise SceneError(f"{obj}: parameter 'image': expected a (height, width, 3) array, got {image.shape}")
            image = np.ascontiguousarray(image[:, :, :3])
        if rotation is not None:
            rotation = np.ascontiguousarray(rotation, dtype=np.float32)
        return self._core.add_light(kind, name, _vec3(obj, "position", position), _vec3(obj, "direction", direction),
                                    c, _number(obj, "intensity", intensity, 0), _number(obj, "temperature", temperature, 0),
                                    _number(obj, "cone_angle", cone_angle), _number(obj, "cone_softness", cone_softness),
                                    _number(obj, "angle", angle), image, rotation)

    def add_point_light(self, position, color=(1, 1, 1), intensity=1.0, temperature=0.0, name="point", **extra):
        """Point light; ``intensity`` scales radiant intensity (W/sr-like units)."""
        _check_keys(f"light '{name}'", extra, [])
        return self._light("point", name, position=position, color=color, intensity=intensity, temperature=temperature)

    def add_spot_light(self, position, direction, cone_angle=30.0, cone_softness=5.0, color=(1, 1, 1),
                       intensity=1.0, temperature=0.0, name="spot", **extra):
        """Spot light: half-angle ``cone_angle`` (degrees), smooth falloff over ``cone_softness``."""
        _check_keys(f"light '{name}'", extra, [])
        return self._light("spot", name, position=position, direction=direction, cone_angle=cone_angle,
                           cone_softness=cone_softness, color=color, intensity=intensity, temperature=temperature)

    def add_distant_light(self, direction, angle=0.0, color=(1, 1, 1), intensity=1.0, temperature=0.0,
                          name="distant", **extra):
        """Directional light travelling along ``direction``; ``angle`` is its angular diameter in
        degrees (0.53 for the sun). ``intensity`` is the irradiance at normal incidence."""
        _check_keys(f"light '{name}'", extra, [])
        return self._light("distant", name, direction=direction, angle=angle, color=color, intensity=intensity,
                           temperature=temperature)

    def add_environment(self, color=(1, 1, 1), image=None, intensity=1.0, rotation=None, name="environment", **extra):
        """Environment light: constant ``color`` or a lat-long ``image`` (array or file path),
        importance-sampled. +Y is up; u = atan2(x, -z) / 2π, v = acos(y) / π."""
        _check_keys(f"light '{name}'", extra, [])
        if isinstance(image, str):
            image = _core.read_rgb_image(image)
        return self._light("environment", name, color=color, intensity=intensity, image=image, rotation=rotation)

    # -- camera
    def set_camera(self, eye=(0, 0, 5), target=(0, 0, 0), up=(0, 1, 0), fov=40.0, fov_axis="x",
                   kind="perspective", width=2.0, aperture_radius=0.0, focus_distance=0.0, **extra):
        """Perspective (``fov`` in degrees along ``fov_axis``; thin lens with ``aperture_radius``,
        focused at ``focus_distance``, default the target) or orthographic (``width`` world units)."""
        _check_keys("camera", extra, [])
        if kind not in ("perspective", "orthographic"):
            raise SceneError(f"camera: parameter 'kind': expected 'perspective' or 'orthographic', got {kind!r}")
        self._core.set_camera(kind, _vec3("camera", "eye", eye), _vec3("camera", "target", target),
                              _vec3("camera", "up", up), _number("camera", "fov", fov), str(fov_axis),
                              _number("camera", "width", width), _number("camera", "aperture_radius", aperture_radius),
                              _number("camera", "focus_distance", focus_distance))
        self.has_camera = True
