"""Export neutral scene descriptions (bench/scenes) to kauri and to Mitsuba 3 and render
them side by side. Only features both renderers model the same way are used: Lambertian
quads (optionally with a bilinear image texture) and flat-shaded triangle meshes, one-sided
diffuse area lights, a pinhole camera, a Gaussian pixel filter (σ = 0.5 px, radius 2 px) or a
box filter of one pixel (`pixel_filter`).

The box is the one filter the three renderers reconstruct identically. Mitsuba 3 splats
with a piecewise-constant table of its Gaussian (`eval_discretized`, 31 steps over the
radius, looked up at the step below), not the Gaussian itself: relative to the centre, its
weight 1.8 px out is 28% above the Gaussian's and its effective σ is 0.512 px, so next to
a bright edge its pixels differ from a true Gaussian's by more than noise
(tests/python/test_peer_agreement.py measures this); Cycles tabulates its filter for
importance sampling. The agreement checks therefore use the box; the speed comparison
uses the Gaussian, kauri's default."""
from __future__ import annotations

import numpy as np

import kauri


def _kauri_material(sh):
    """Lobes both renderers define alike; GGX α maps to kauri's roughness = √α."""
    if "conductor" in sh:
        c = sh["conductor"]
        return kauri.Conductor(metal=c["metal"], roughness=c["alpha"] ** 0.5, compensate=False, name=sh["name"])
    if "dielectric" in sh:
        d = sh["dielectric"]
        return kauri.RoughDielectric(ior=d["ior"], roughness=d["alpha"] ** 0.5, compensate=False, name=sh["name"])
    if "texture" in sh:
        return kauri.Lambert(albedo=kauri.ImageTexture(sh["texture"], name=sh["name"]), name=sh["name"])
    return kauri.Lambert(albedo=sh["diffuse"], name=sh["name"])


def _mitsuba_bsdf(sh):
    if "conductor" in sh:
        c = sh["conductor"]
        return {"type": "roughconductor", "material": c["metal"], "distribution": "ggx", "alpha": c["alpha"]}
    if "dielectric" in sh:
        d = sh["dielectric"]
        return {"type": "roughdielectric", "int_ior": d["ior"], "ext_ior": 1.0, "distribution": "ggx",
                "alpha": d["alpha"]}
    if "texture" in sh:
        # Mitsuba's rectangle puts image row 0 at v = 0; kauri (like OpenGL / USD) at v = 1.
        import mitsuba as mi
        return {"type": "diffuse", "reflectance": {
            "type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(np.flipud(sh["texture"]))),
            "filter_type": "bilinear", "wrap_mode": "repeat", "raw": False,
            "to_uv": mi.ScalarTransform4f().scale([sh.get("uv_scale", 1), sh.get("uv_scale", 1), 1])}}
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(sh["diffuse"])}}


def to_kauri(desc) -> kauri.Scene:
    s = kauri.Scene(color_space=desc["color_space"])
    for sh in desc["shapes"]:
        if "sphere" in sh:
            (center, radius) = sh["sphere"]
            s.add_sphere(center=center, radius=radius, material=_kauri_material(sh), name=sh["name"])
            continue
        if "mesh" in sh:
            (P, F) = sh["mesh"]
            s.add_mesh(P, F, material=_kauri_material(sh), name=sh["name"])
            continue
        P = np.array(sh["quad"], np.float32)
        I = np.array([[0, 1, 2, 3]])
        if "emission" in sh:
            e = sh["emission"]
            peak = max(e)
            s.add_mesh(P, I, emission=kauri.Emission(color=tuple(c / peak for c in e), intensity=peak),
                       name=sh["name"])
        else:
            k = sh.get("uv_scale", 1)
            uv = np.array([(0, 0), (k, 0), (k, k), (0, k)], np.float32)
            s.add_mesh(P, I, uvs=uv, material=_kauri_material(sh), name=sh["name"])
    if "environment" in desc:
        s.add_environment(image=desc["environment"])
    if "environment_color" in desc:
        s.add_environment(color=desc["environment_color"])
    c = desc["camera"]
    s.set_camera(eye=c["eye"], target=c["target"], up=c["up"], fov=c["fov_x"], fov_axis="x")
    return s


def _rectangle_to_world(quad):
    """Mitsuba's rectangle is [-1, 1]² in z = 0 facing +z; map it onto parallelogram a b c d."""
    a, b, c, d = (np.asarray(p, float) for p in quad)
    u, v = (b - a) / 2, (d - a) / 2
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    M = np.eye(4)
    M[:3, 0], M[:3, 1], M[:3, 2], M[:3, 3] = u, v, n, (a + c) / 2
    return M


def mitsuba_latlong(img):
    """kauri puts lat-long row y at v = (y + 0.5) / h (texel centres, bilinear between them,
    constant from the first / last centre to the pole); Mitsuba 3's envmap puts row y at
    v = y / (h − 1), its first and last rows on the poles (columns at centres, as kauri).
    Resampling kauri's reconstruction at v = k / 2h, k = 0..2h, hits every row centre of
    kauri's image, so Mitsuba's bilinear lookup of the result equals kauri's exactly."""
    img = np.asarray(img, np.float64)
    h = img.shape[0]
    v = np.arange(2 * h + 1) / (2 * h)
    f = np.clip(v * h - 0.5, 0, h - 1)
    y0 = np.minimum(np.floor(f).astype(int), h - 2) if h > 1 else np.zeros_like(f, int)
    t = (f - y0)[:, None, None]
    y1 = np.minimum(y0 + 1, h - 1)
    return ((1 - t) * img[y0] + t * img[y1]).astype(np.float32)


PIXEL_FILTERS = ("gaussian", "box")


def _check_filter(pixel_filter):
    if pixel_filter not in PIXEL_FILTERS:
        raise ValueError(f"pixel_filter must be one of {PIXEL_FILTERS}, not {pixel_filter!r}")


def _mitsuba_filter(pixel_filter):
    _check_filter(pixel_filter)
    return {"type": "gaussian", "stddev": 0.5} if pixel_filter == "gaussian" else {"type": "box"}


def _kauri_filter(pixel_filter):
    _check_filter(pixel_filter)
    return {"filter": "gaussian", "filter_sigma": 0.5, "filter_radius": 2.0} if pixel_filter == "gaussian" else \
        {"filter": "box", "filter_radius": 0.5}


def to_mitsuba(desc, spp=64, resolution=(64, 64), max_depth=65, pixel_filter="gaussian", sampler="independent"):
    """A Mitsuba 3 scene dict (load with mi.load_dict after mi.set_variant). `sampler`: a
    Mitsuba sampler plugin; "independent" (Mitsuba's default) takes any spp, the stratified
    ones ("stratified", "multijitter") round some counts up (squares are kept)."""
    import mitsuba as mi
    cam = desc["camera"]
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": max_depth},
         "sensor": {"type": "perspective", "fov": cam["fov_x"], "fov_axis": "x",
                    "to_world": mi.ScalarTransform4f().look_at(origin=list(map(float, cam["eye"])),
                                                               target=list(map(float, cam["target"])),
                                                               up=list(map(float, cam["up"]))),
                    "sampler": {"type": sampler, "sample_count": spp},
                    "film": {"type": "hdrfilm", "width": resolution[0], "height": resolution[1],
                             "rfilter": _mitsuba_filter(pixel_filter), "pixel_format": "rgb"}}}
    if "environment" in desc:
        d["sky"] = {"type": "envmap", "bitmap": mi.Bitmap(mitsuba_latlong(desc["environment"]))}
    if "environment_color" in desc:
        d["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(desc["environment_color"])}}
    for sh in desc["shapes"]:
        if "sphere" in sh:
            (center, radius) = sh["sphere"]
            d[sh["name"]] = {"type": "sphere", "center": list(map(float, center)), "radius": float(radius),
                             "bsdf": _mitsuba_bsdf(sh)}
            continue
        if "mesh" in sh:
            # Flat shading in both: kauri's meshes without normals use the face normal;
            # Mitsuba's PLY loader would interpolate vertex normals unless told not to.
            d[sh["name"]] = {"type": "ply", "filename": _ply_file(*sh["mesh"]), "face_normals": True,
                             "bsdf": {"type": "twosided", "bsdf": _mitsuba_bsdf(sh)}}
            continue
        shape = {"type": "rectangle", "to_world": mi.ScalarTransform4f(_rectangle_to_world(sh["quad"]).tolist())}
        if "emission" in sh:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(sh["emission"])}}
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
        else:
            # kauri's materials shade both sides alike (symmetric stacks); Mitsuba's BSDFs
            # are black from behind unless wrapped in `twosided`. Open quads are seen from
            # both sides (the hangar's crate fronts from the back wall), so wrap them.
            bsdf = _mitsuba_bsdf(sh)
            shape["bsdf"] = bsdf if bsdf["type"] == "roughdielectric" else {"type": "twosided", "bsdf": bsdf}
        d[sh["name"]] = shape
    return d


def _ply_file(positions, triangles):
    """A binary PLY of the mesh for Mitsuba's loader, in the temporary directory, named by
    a hash of its contents (written once, atomically; later calls reuse it)."""
    import hashlib
    import os
    import tempfile
    P = np.ascontiguousarray(positions, "<f4")
    F = np.ascontiguousarray(triangles, "<i4")
    key = hashlib.sha1(P.tobytes() + F.tobytes()).hexdigest()[:16]
    path = os.path.join(tempfile.gettempdir(), f"kauri_peers_{key}.ply")
    if os.path.exists(path):
        return path
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(P)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    faces = np.empty(len(F), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"] = 3
    faces["v"] = F
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), suffix=".ply.tmp")
    with os.fdopen(fd, "wb") as f:
        f.write(header)
        f.write(P.tobytes())
        f.write(faces.tobytes())
    os.replace(tmp, path)
    return path


def render_mitsuba(desc, variant="scalar_rgb", spp=64, resolution=(64, 64), seed=0, pixel_filter="gaussian",
                   sampler="independent"):
    import mitsuba as mi
    mi.set_variant(variant)
    scene = mi.load_dict(to_mitsuba(desc, spp, resolution, pixel_filter=pixel_filter, sampler=sampler))
    n = scene.sensors()[0].sampler().sample_count()
    if n != spp:
        raise ValueError(f"Mitsuba's {sampler!r} sampler renders {n} samples per pixel, not the {spp} asked for "
                         f"(it rounds some counts up): use a square spp or the 'independent' sampler")
    return np.array(mi.render(scene, seed=seed), dtype=np.float64)


_last_kauri_scene = (None, None)  # (description, its kauri.Scene)


def kauri_scene(desc) -> kauri.Scene:
    """The kauri scene of a description, kept for the next call with the same description
    object: kauri.render then reuses its compiled form (BVH, lights), as Mitsuba renders a
    loaded scene again without rebuilding it."""
    global _last_kauri_scene
    if _last_kauri_scene[0] is not desc:
        _last_kauri_scene = (desc, to_kauri(desc))
    return _last_kauri_scene[1]


# Path-length limits of kauri's renders here: as good as unlimited (Russian roulette ends
# paths), like Mitsuba's max_depth 65 (to_mitsuba) and Cycles' 64 bounces.
KAURI_PATH_LIMITS = dict(max_depth=64, max_diffuse=64, max_glossy=64, max_transmission=64)


def render_kauri(desc, spp=64, resolution=(64, 64), seed=0, pixel_filter="gaussian"):
    # The beauty alone, like Mitsuba's film here (kauri's albedo / normal / depth AOVs are not compared).
    out = kauri.render(kauri_scene(desc), spp=spp, resolution=resolution, seed=seed, aovs=False,
                       **KAURI_PATH_LIMITS, **_kauri_filter(pixel_filter))
    return out.rgba[:, :, :3].astype(np.float64)


# ---------------------------------------------------------------------------------------
# Blender's Cycles (bench/cycles_peer.py in a Python that has bpy)

def cycles_python(explicit=None):
    """The Python interpreter with `bpy` for the Cycles peer, or None: `explicit`, else
    $KAURI_BPY_PYTHON, else the virtual environment scripts/setup_cycles makes
    ($KAURI_BPY_VENV, default ~/.cache/kauri/bpy-venv)."""
    import os
    if explicit:
        return explicit
    if os.environ.get("KAURI_BPY_PYTHON"):
        return os.environ["KAURI_BPY_PYTHON"]
    venv = os.environ.get("KAURI_BPY_VENV", os.path.join(os.path.expanduser("~"), ".cache", "kauri", "bpy-venv"))
    py = os.path.join(venv, "bin", "python")
    return py if os.path.exists(py) else None


def metal_rgb(desc):
    """RGB η and k of the description's measured metals, as Mitsuba 3's RGB variants use
    them (its own reduction of the same tables): Cycles is an RGB renderer and needs them."""
    metals = sorted({sh["conductor"]["metal"] for sh in desc["shapes"] if "conductor" in sh})
    if not metals:
        return {}
    import mitsuba as mi
    if "scalar_rgb" not in mi.variants():
        raise RuntimeError("the RGB of measured metals comes from Mitsuba's scalar_rgb variant, not available")
    previous = mi.variant()
    mi.set_variant("scalar_rgb")
    try:
        out = {}
        for m in metals:
            p = mi.traverse(mi.load_dict({"type": "roughconductor", "material": m, "distribution": "ggx"}))
            out[m] = {"eta": [float(x) for x in p["eta.value"]], "k": [float(x) for x in p["k.value"]]}
        return out
    finally:
        if previous:
            mi.set_variant(previous)


class CyclesPeer:
    """Client of a long-lived `cycles_peer.py --serve` process. render(desc, ...) renders
    the bench scene named desc["name"] (the server builds scenes.<name>.describe() itself:
    the descriptions hold arrays and the two Pythons have different NumPy majors) and
    returns (image (H, W, 3) float64, wall s, CPU s) as timed inside the server around
    Cycles' render call."""

    def __init__(self, python=None, log_path=None):
        import os
        import subprocess
        import tempfile
        self.python = cycles_python(python)
        if not self.python:
            raise RuntimeError("no Python with bpy: run scripts/setup_cycles (or set KAURI_BPY_PYTHON)")
        self._dir = tempfile.mkdtemp(prefix="kauri_cycles_")
        self._log = open(log_path or os.path.join(self._dir, "blender.log"), "w")
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cycles_peer.py")
        self._proc = subprocess.Popen([self.python, script, "--serve"], stdin=subprocess.PIPE,
                                      stdout=subprocess.PIPE, stderr=self._log, text=True)
        self._metals = {}
        self._n = 0
        self.version = None  # Blender's version string, from the first reply

    def render(self, desc, spp, resolution, seed, threads, pixel_filter="gaussian"):
        import json
        import os
        _check_filter(pixel_filter)
        name = desc["name"]
        if name not in self._metals:
            self._metals[name] = metal_rgb(desc)
        self._n += 1
        out = os.path.join(self._dir, f"render_{self._n}.npy")
        req = {"scene": name, "spp": int(spp), "res": int(resolution[0]), "seed": int(seed),
               "threads": int(threads), "metal_rgb": self._metals[name], "pixel_filter": pixel_filter, "out": out}
        if resolution[0] != resolution[1]:
            raise ValueError("CyclesPeer renders square images")
        self._proc.stdin.write(json.dumps(req) + "\n")
        self._proc.stdin.flush()
        line = self._proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the Cycles server exited (status {self._proc.poll()}); its log: {self._log.name}")
        reply = json.loads(line)
        if not reply["ok"]:
            raise RuntimeError(f"Cycles: {reply['error']}")
        self.version = reply.get("blender")
        img = np.load(out).astype(np.float64)
        os.unlink(out)
        return img, reply["wall"], reply["cpu"]

    def cpu_seconds(self):
        """CPU time (user + system) the server has used so far, from /proc; 0 once it exited."""
        import os
        try:
            with open(f"/proc/{self._proc.pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime
        except (OSError, ValueError, IndexError):
            return 0.0

    def close(self):
        import shutil
        if self._proc.poll() is None:
            self._proc.stdin.close()
            try:
                self._proc.wait(timeout=30)
            except Exception:  # noqa: BLE001
                self._proc.kill()
        self._log.close()
        shutil.rmtree(self._dir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
