"""Blender's Cycles as a third peer: builds a bench/scenes description in Cycles and renders
it. This file runs in a Python that has `bpy` (Blender as a module), which pins NumPy 1.x
and so lives in its own virtual environment (bench/setup_cycles.sh makes one); the suite
talks to it through a subprocess (`serve`, one JSON request per line) and never imports it.

The mapping is the one peers.py makes for Mitsuba, feature by feature:
- Lambertian quads and flat-shaded triangle meshes: Diffuse BSDF at roughness 0 (Cycles'
  Lambert); textures as Image Texture nodes, bilinear ('Linear'), repeating, raw values
  (the descriptions give linear sRGB, Cycles' scene-linear space).
- One-sided area lights: an Emission shader of strength 1 (radiance = the colour) on the
  front side, black behind (Geometry › Backfacing), and light sampling of the front only
  (material emission_sampling = 'FRONT'). Front is the side of (b − a) × (d − a), as in
  kauri and in Mitsuba's rectangle.
- Spheres: Cycles' point-cloud points are exact ray-traced spheres with smooth normals; one
  point per sphere, made by a geometry-nodes modifier. Not for glass: points do not refract
  like a solid sphere, so dielectric spheres are smooth meshes of 512 × 256 segments.
- Rough conductor and rough dielectric: single-scattering GGX ('GGX', not 'MULTI_GGX';
  Cycles' roughness r has α = r²), the conductor with the Physical Conductor Fresnel at RGB
  η and k. Cycles is an RGB renderer, so a measured metal's spectra must come as RGB: the
  caller passes `metal_rgb` (the suite uses Mitsuba's own RGB values of the same table).
- Environment maps: the lat-long lookup is built from math nodes with kauri's convention
  (u = atan2(x, −z)/2π, v = acos(y)/π, +Y up) rather than Blender's Z-up Environment
  Texture; the image is padded by one wrapped column on each side and one repeated row at
  each pole, so Cycles' bilinear lookup equals kauri's (wraps in u, constant from the
  first / last row centre to the pole).
- Camera: pinhole with the horizontal field of view; pixel filter Gaussian with σ = 0.5 px
  as kauri and Mitsuba here, or a one-pixel box (the agreement checks, see peers.py).
  Cycles' 'GAUSSIAN' is set by a width, and the width that reproduces σ = 0.5 px was
  measured: fitting kauri − Cycles (converged cornell, 64×64) as gain + shift + c·∇² gives
  c = −2.1 at width 6, −0.71 at 4, −0.28 at 3, −0.12 at 2.5, −0.006 at 2 and +0.06 at 1.5;
  so width 2 (tests/python/test_cycles_peer.py checks it, and the box).
- Sampling as Cycles users get it (light tree, its default sampling pattern), without
  adaptive sampling, denoising or clamping; max depth as peers.py gives the others.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time

import numpy as np

BENCH = os.path.dirname(os.path.abspath(__file__))
if BENCH not in sys.path:
    sys.path.insert(0, BENCH)

from procinfo import vmhwm_kib  # noqa: E402

MAX_BOUNCES = 64  # as peers.render_kauri (max_depth=64) and peers.to_mitsuba (max_depth=65)
GAUSSIAN_WIDTH = 2.0  # px: reproduces the sigma = 0.5 px Gaussian of kauri and Mitsuba (docstring)


def _bpy():
    import bpy  # only in the bpy environment
    return bpy


# ---------------------------------------------------------------------------------------
# Materials

def _new_material(name):
    bpy = _bpy()
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes.clear()
    out = m.node_tree.nodes.new("ShaderNodeOutputMaterial")
    return m, m.node_tree, out


def _image(name, pixels, colorspace="Non-Color"):
    """A float Blender image of an (H, W, 3) array whose row 0 is the top (Blender stores
    rows bottom-up)."""
    bpy = _bpy()
    pixels = np.asarray(pixels, np.float32)
    h, w = pixels.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    img.colorspace_settings.name = colorspace
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = np.flipud(pixels[..., :3])
    img.pixels.foreach_set(rgba.ravel())
    img.pack()  # keep the pixels with the file (a generated image has no source on disk)
    return img


def material(sh, metal_rgb):
    """The Cycles material of a description shape (see the module docstring)."""
    m, nt, out = _new_material(sh["name"])
    if "emission" in sh:
        e = nt.nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (*map(float, sh["emission"]), 1.0)
        e.inputs["Strength"].default_value = 1.0
        black = nt.nodes.new("ShaderNodeBsdfDiffuse")
        black.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(geo.outputs["Backfacing"], mix.inputs[0])
        nt.links.new(e.outputs[0], mix.inputs[1])
        nt.links.new(black.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
        m.cycles.emission_sampling = "FRONT"
        return m
    if "conductor" in sh:
        c = sh["conductor"]
        if c["metal"] not in metal_rgb:
            raise ValueError(f"shape {sh['name']!r}: no RGB eta/k for metal {c['metal']!r} (pass metal_rgb)")
        b = nt.nodes.new("ShaderNodeBsdfMetallic")
        b.distribution = "GGX"
        b.fresnel_type = "PHYSICAL_CONDUCTOR"
        b.inputs["IOR"].default_value = tuple(map(float, metal_rgb[c["metal"]]["eta"]))
        b.inputs["Extinction"].default_value = tuple(map(float, metal_rgb[c["metal"]]["k"]))
        b.inputs["Roughness"].default_value = math.sqrt(c["alpha"])
    elif "dielectric" in sh:
        d = sh["dielectric"]
        b = nt.nodes.new("ShaderNodeBsdfGlass")
        b.distribution = "GGX"
        b.inputs["IOR"].default_value = float(d["ior"])
        b.inputs["Roughness"].default_value = math.sqrt(d["alpha"])
        b.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    else:
        b = nt.nodes.new("ShaderNodeBsdfDiffuse")
        b.inputs["Roughness"].default_value = 0.0
        if "texture" in sh:
            tex = nt.nodes.new("ShaderNodeTexImage")
            tex.image = _image(sh["name"], sh["texture"])
            tex.interpolation = "Linear"
            tex.extension = "REPEAT"
            uv = nt.nodes.new("ShaderNodeTexCoord")
            nt.links.new(uv.outputs["UV"], tex.inputs["Vector"])
            nt.links.new(tex.outputs["Color"], b.inputs["Color"])
        else:
            b.inputs["Color"].default_value = (*map(float, sh["diffuse"]), 1.0)
    nt.links.new(b.outputs[0], out.inputs["Surface"])
    return m


# ---------------------------------------------------------------------------------------
# Shapes

def _link(obj):
    _bpy().context.scene.collection.objects.link(obj)
    return obj


def add_quad(sh, mat):
    bpy = _bpy()
    me = bpy.data.meshes.new(sh["name"])
    me.from_pydata([tuple(map(float, p)) for p in sh["quad"]], [], [(0, 1, 2, 3)])
    k = float(sh.get("uv_scale", 1))
    layer = me.uv_layers.new(name="UVMap")
    for loop, uv in zip(layer.data, ((0, 0), (k, 0), (k, k), (0, k))):
        loop.uv = uv
    me.materials.append(mat)
    return _link(bpy.data.objects.new(sh["name"], me))


def add_mesh(sh, mat):
    """Triangles through foreach_set (a million of them in a few seconds); flat shaded."""
    bpy = _bpy()
    P, F = (np.asarray(a) for a in sh["mesh"])
    me = bpy.data.meshes.new(sh["name"])
    me.vertices.add(len(P))
    me.vertices.foreach_set("co", np.ascontiguousarray(P, np.float32).ravel())
    me.loops.add(3 * len(F))
    me.loops.foreach_set("vertex_index", np.ascontiguousarray(F, np.int32).ravel())
    me.polygons.add(len(F))
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * len(F), 3, dtype=np.int32))
    me.update()
    me.materials.append(mat)
    return _link(bpy.data.objects.new(sh["name"], me))


def add_sphere(sh, mat):
    """Opaque spheres: one point of a point cloud (an exact sphere in Cycles), from a
    geometry-nodes modifier. Dielectric spheres: a finely tessellated, smooth-shaded mesh,
    because Cycles' points do not refract like a solid sphere: a rough-glass point came out
    up to 19% off kauri and Mitsuba per 8×8-pixel block, the mesh within 1%."""
    bpy = _bpy()
    (center, radius) = sh["sphere"]
    if "dielectric" in sh:
        return _mesh_sphere(sh["name"], center, radius, mat)
    ng = bpy.data.node_groups.new(sh["name"], "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    pts = ng.nodes.new("GeometryNodePoints")
    pts.inputs["Count"].default_value = 1
    pts.inputs["Position"].default_value = tuple(map(float, center))
    pts.inputs["Radius"].default_value = float(radius)
    setm = ng.nodes.new("GeometryNodeSetMaterial")
    setm.inputs["Material"].default_value = mat
    out = ng.nodes.new("NodeGroupOutput")
    ng.links.new(pts.outputs["Geometry"], setm.inputs["Geometry"])
    ng.links.new(setm.outputs["Geometry"], out.inputs[0])
    obj = _link(bpy.data.objects.new(sh["name"], bpy.data.meshes.new(sh["name"])))
    obj.modifiers.new("sphere", "NODES").node_group = ng
    return obj


SPHERE_SEGMENTS = (512, 256)  # silhouette within r (1 - cos(pi / 256)) = 7.5e-5 r of the sphere


def sphere_triangles(n_phi, n_theta):
    """Unit sphere as a lat-long triangle mesh: (positions (V, 3), triangles (F, 3)), counter-
    clockwise seen from outside (outward geometric normals, which Cycles' glass needs to tell
    entering from leaving). Poles are single vertices; every band quad is split in two."""
    theta = np.pi * np.arange(1, n_theta) / n_theta
    phi = 2 * np.pi * np.arange(n_phi) / n_phi
    T, P = np.meshgrid(theta, phi, indexing="ij")
    rings = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    pos = np.concatenate([[(0.0, 0.0, 1.0)], rings, [(0.0, 0.0, -1.0)]])
    top, bottom = 0, len(pos) - 1
    i = np.arange(n_phi)
    j = (i + 1) % n_phi

    def ring(k, idx):
        return 1 + k * n_phi + idx

    tris = [np.stack([np.full(n_phi, top), ring(0, i), ring(0, j)], -1)]
    for k in range(n_theta - 2):
        a, b, c, d = ring(k, i), ring(k + 1, i), ring(k + 1, j), ring(k, j)
        tris += [np.stack([a, b, c], -1), np.stack([a, c, d], -1)]
    tris.append(np.stack([ring(n_theta - 2, i), np.full(n_phi, bottom), ring(n_theta - 2, j)], -1))
    return pos, np.concatenate(tris).astype(np.int32)


def _mesh_sphere(name, center, radius, mat):
    P, F = sphere_triangles(*SPHERE_SEGMENTS)
    obj = add_mesh({"name": name, "mesh": (P * float(radius) + np.asarray(center, float), F)}, mat)
    obj.data.polygons.foreach_set("use_smooth", np.ones(len(F), dtype=bool))
    obj.data.update()
    return obj


# ---------------------------------------------------------------------------------------
# World, camera, render settings

def _latlong_padded(img):
    """(H, W, 3) lat-long -> (H + 2, W + 2, 3): one wrapped column each side, the first and
    last rows repeated, so a clamped bilinear lookup at s = (u W + 1)/(W + 2),
    t = (v H + 1)/(H + 2) reproduces kauri's reconstruction everywhere."""
    img = np.asarray(img, np.float32)
    img = np.concatenate([img[:, -1:], img, img[:, :1]], axis=1)
    return np.concatenate([img[:1], img, img[-1:]], axis=0)


def _math(nt, op, a, b=None):
    n = nt.nodes.new("ShaderNodeMath")
    n.operation = op
    for i, x in enumerate((a, b)):
        if x is None:
            continue
        if isinstance(x, (int, float)):
            n.inputs[i].default_value = float(x)
        else:
            nt.links.new(x, n.inputs[i])
    return n.outputs[0]


def set_world(desc):
    bpy = _bpy()
    world = bpy.data.worlds.new("world")
    bpy.context.scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    bg = nt.nodes["Background"]
    bg.inputs["Strength"].default_value = 1.0
    if "environment" in desc:
        env = np.asarray(desc["environment"], np.float32)
        h, w = env.shape[:2]
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.image = _image("environment", _latlong_padded(env))
        tex.interpolation = "Linear"
        tex.extension = "EXTEND"
        # Direction d of the background ray: u = atan2(x, -z) / 2pi wrapped to [0, 1),
        # v = acos(y) / pi (kauri's light.h); image t runs bottom-up, t = 1 - v.
        # (Generated, in a world shader, is that direction; normalised to be safe.)
        norm = nt.nodes.new("ShaderNodeVectorMath")
        norm.operation = "NORMALIZE"
        nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"], norm.inputs[0])
        d = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(norm.outputs[0], d.inputs[0])
        x, y, z = d.outputs["X"], d.outputs["Y"], d.outputs["Z"]
        u = _math(nt, "WRAP", _math(nt, "MULTIPLY", _math(nt, "ARCTAN2", x, _math(nt, "MULTIPLY", z, -1.0)),
                                    1 / (2 * math.pi)), 1.0)
        u.node.inputs[2].default_value = 0.0  # WRAP(value, max = 1, min = 0)
        v = _math(nt, "MULTIPLY", _math(nt, "ARCCOSINE", _math(nt, "MINIMUM", _math(nt, "MAXIMUM", y, -1.0), 1.0)),
                  1 / math.pi)
        s = _math(nt, "DIVIDE", _math(nt, "ADD", _math(nt, "MULTIPLY", u, float(w)), 1.0), float(w + 2))
        t = _math(nt, "DIVIDE", _math(nt, "ADD", _math(nt, "MULTIPLY", _math(nt, "SUBTRACT", 1.0, v), float(h)), 1.0),
                  float(h + 2))
        st = nt.nodes.new("ShaderNodeCombineXYZ")
        nt.links.new(s, st.inputs["X"])
        nt.links.new(t, st.inputs["Y"])
        nt.links.new(st.outputs[0], tex.inputs["Vector"])
        nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
    else:
        rgb = desc.get("environment_color", (0.0, 0.0, 0.0))
        bg.inputs["Color"].default_value = (*map(float, rgb), 1.0)


def set_camera(desc):
    from mathutils import Matrix, Vector
    bpy = _bpy()
    c = desc["camera"]
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "HORIZONTAL"
    cam.angle = math.radians(c["fov_x"])
    cam.clip_start = 1e-4
    cam.clip_end = 1e6
    obj = _link(bpy.data.objects.new("camera", cam))
    bpy.context.scene.camera = obj
    eye, target, up = Vector(c["eye"]), Vector(c["target"]), Vector(c["up"])
    f = (target - eye).normalized()
    r = f.cross(up).normalized()
    u = r.cross(f)
    # Blender cameras look down their local -Z with +Y up.
    obj.matrix_world = Matrix(((r.x, u.x, -f.x, eye.x), (r.y, u.y, -f.y, eye.y), (r.z, u.z, -f.z, eye.z),
                               (0.0, 0.0, 0.0, 1.0)))


def build_scene(desc, metal_rgb=None):
    """Replaces Blender's current file with the Cycles scene of `desc`."""
    bpy = _bpy()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    metal_rgb = metal_rgb or {}
    for sh in desc["shapes"]:
        mat = material(sh, metal_rgb)
        if "sphere" in sh:
            add_sphere(sh, mat)
        elif "mesh" in sh:
            add_mesh(sh, mat)
        elif "quad" in sh:
            add_quad(sh, mat)
        else:
            raise ValueError(f"shape {sh.get('name')!r}: no Cycles mapping for keys {sorted(sh)}")
    set_world(desc)
    set_camera(desc)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = MAX_BOUNCES
    cy.transparent_max_bounces = MAX_BOUNCES
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    cy.use_animated_seed = False
    set_pixel_filter(scene, "gaussian")
    scene.render.resolution_percentage = 100
    scene.render.use_persistent_data = True  # keep the BVH between renders of this scene
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "NONE"


def set_pixel_filter(scene, pixel_filter):
    """"gaussian": σ = 0.5 px (GAUSSIAN_WIDTH); "box": one pixel (Cycles' box of width 1
    draws the position uniformly in the pixel, the box splat's expectation)."""
    if pixel_filter == "gaussian":
        scene.cycles.pixel_filter_type, scene.cycles.filter_width = "GAUSSIAN", GAUSSIAN_WIDTH
    elif pixel_filter == "box":
        scene.cycles.pixel_filter_type, scene.cycles.filter_width = "BOX", 1.0
    else:
        raise ValueError(f"pixel_filter must be 'gaussian' or 'box', not {pixel_filter!r}")


def render(spp, resolution, seed, threads, pixel_filter="gaussian"):
    """Renders the current scene; returns ((H, W, 3) float32 linear RGB, wall s, CPU s).
    Only bpy.ops.render.render is timed (as Mitsuba's mi.render, after load_dict)."""
    bpy = _bpy()
    scene = bpy.context.scene
    set_pixel_filter(scene, pixel_filter)
    scene.cycles.samples = int(spp)
    scene.cycles.seed = int(seed)
    scene.render.resolution_x, scene.render.resolution_y = int(resolution[0]), int(resolution[1])
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(threads)
    t0, c0 = time.perf_counter(), time.process_time()
    bpy.ops.render.render(write_still=False)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    fd, path = tempfile.mkstemp(suffix=".exr")
    os.close(fd)
    try:
        bpy.data.images["Render Result"].save_render(path)
        img = bpy.data.images.load(path)
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        bpy.data.images.remove(img)
    finally:
        os.unlink(path)
    return np.flipud(px.reshape(h, w, 4))[..., :3].copy(), wall, cpu


# ---------------------------------------------------------------------------------------
# Entry points (run with the bpy Python)

def _describe(name):
    import importlib
    return importlib.import_module(f"scenes.{name}").describe()


def serve(stdin=sys.stdin, stdout=sys.stdout):
    """One JSON request per line: {"scene", "spp", "res", "seed", "threads", "metal_rgb",
    "pixel_filter" (optional: "gaussian", the default, or "box"), "out"}; renders scene
    `scenes.<scene>.describe()` (built once while the same scene is asked for), saves the
    image to `out` (.npy) and answers {"ok", "wall", "cpu"} or {"ok": false, "error"}.
    Blender's own log goes to stderr."""
    current = None
    for line in stdin:
        if not line.strip():
            continue
        try:
            req = json.loads(line)
            key = (req["scene"], json.dumps(req.get("metal_rgb"), sort_keys=True))
            if key != current:
                current = None
                build_scene(_describe(req["scene"]), req.get("metal_rgb"))
                current = key
            img, wall, cpu = render(req["spp"], (req["res"], req["res"]), req["seed"], req["threads"],
                                    req.get("pixel_filter", "gaussian"))
            tmp = req["out"] + ".tmp.npy"
            np.save(tmp, img)
            os.replace(tmp, req["out"])
            reply = {"ok": True, "wall": wall, "cpu": cpu, "blender": _bpy().app.version_string}
        except Exception as e:  # noqa: BLE001 - reported to the client
            reply = {"ok": False, "error": f"{type(e).__name__}: {e}"}
        stdout.write(json.dumps(reply) + "\n")
        stdout.flush()


def main(argv=None):
    p = argparse.ArgumentParser(description="Cycles peer for bench/suite.py (run with a Python that has bpy).")
    p.add_argument("--serve", action="store_true", help="answer JSON render requests on stdin (the suite's client)")
    p.add_argument("--scene", help="one render (or, with --baseline, only the scene build) of bench/scenes/<scene>")
    p.add_argument("--res", type=int, default=32)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--threads", type=int, default=os.cpu_count())
    p.add_argument("--metal-rgb", default="{}", help="JSON {metal: {eta: [r, g, b], k: [r, g, b]}}")
    p.add_argument("--baseline", action="store_true", help="build the scene, do not render")
    args = p.parse_args(argv)
    if args.serve:
        # Blender prints its progress on stdout; the protocol needs stdout to itself.
        proto = os.fdopen(os.dup(sys.stdout.fileno()), "w")
        os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
        serve(sys.stdin, proto)
        return 0
    if not args.scene:
        p.error("--scene or --serve is required")
    build_scene(_describe(args.scene), json.loads(args.metal_rgb))
    out = {"built": args.scene}
    if not args.baseline:
        img, wall, _ = render(args.spp, (args.res, args.res), 1, args.threads)
        out.update(mean=float(img.mean()), wall=wall)
    out["vmhwm_kib"] = vmhwm_kib()
    print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
