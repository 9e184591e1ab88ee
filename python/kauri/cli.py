"""The ``kauri`` command line."""
from __future__ import annotations

import argparse
import importlib.util
import os
import sys
import time

DEMO_SPP = 80
DEMO_CLAMP = 8.0
DEMO_RES = "512x512"


def _parse_res(text: str):
    try:
        w, h = text.lower().split("x")
        w, h = int(w), int(h)
        if w <= 0 or h <= 0:
            raise ValueError
        return w, h
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT (e.g. 1280x720), got {text!r}") from None


def _load_scene(path: str):
    """A scene file for now is a Python file whose build() returns a kauri.Scene."""
    from .scene import Scene
    if not os.path.isfile(path):
        raise SystemExit(f"kauri: error: {path}: no such file")
    if not path.endswith(".py"):
        raise SystemExit(f"kauri: error: {path}: unsupported scene format (expected a .py file with build())")
    spec = importlib.util.spec_from_file_location("kauri_user_scene", path)
    module = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(module)
    except Exception as e:  # report where the user's file failed
        raise SystemExit(f"kauri: error: {path}: {type(e).__name__}: {e}") from None
    if not hasattr(module, "build"):
        raise SystemExit(f"kauri: error: {path}: defines no build() function returning a kauri.Scene")
    try:
        scene = module.build()
    except ValueError as e:  # scene errors name the object and parameter
        raise SystemExit(f"kauri: error: {path}: {e}") from None
    if not isinstance(scene, Scene):
        raise SystemExit(f"kauri: error: {path}: build() returned {type(scene).__name__}, expected kauri.Scene")
    return scene


def _cmd_render(args) -> int:
    from . import demo, render
    from .scene import SceneError
    scene = _load_scene(args.scene) if args.scene else demo.build()
    out = args.output
    if not out.lower().endswith(".exr"):
        print(f"kauri: error: -o {out}: the output must be an .exr file", file=sys.stderr)
        return 2
    w, h = args.res
    clamp = args.clamp if args.clamp is not None else (0.0 if args.scene else DEMO_CLAMP)
    print(f"kauri: rendering {args.scene or 'built-in demo scene'} at {w}x{h}, {args.spp} spp"
          + (f", time limit {args.time_limit:g} s" if args.time_limit else ""), file=sys.stderr)
    try:
        result = render(scene, spp=args.spp, resolution=(w, h), seed=args.seed, threads=args.threads,
                        time_limit=args.time_limit, max_depth=args.max_depth, clamp=clamp,
                        sampler=args.sampler, reconstruction=args.reconstruction, progress=not args.quiet,
                        aovs=not args.no_aovs, light_sampler=args.light_sampler, rr_depth=args.rr_depth,
                        light_aa=args.light_aa, path_lanes=not args.no_path_lanes)
    except (SceneError, ValueError) as e:
        print(f"kauri: error: {e}", file=sys.stderr)
        return 2
    result.write_exr(out, scene_name=args.scene or "demo")
    png = os.path.splitext(out)[0] + ".png"
    if not args.no_preview:
        result.write_png(png, exposure=args.exposure)
    print(result.stats["summary"], file=sys.stderr)
    print(f"kauri: wrote {out}" + ("" if args.no_preview else f" and {png}"), file=sys.stderr)
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="kauri", description="kauri: a spectral production path tracer.")
    p.add_argument("--version", action="store_true", help="print the version and exit")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    r = sub.add_parser("render", help="render a scene to an EXR (and a PNG preview)",
                       description="Render SCENE (a Python file whose build() returns a kauri.Scene) or, "
                                   "without SCENE, the built-in demo scene. Writes a multi-channel EXR "
                                   "(beauty RGBA, albedo, normal, depth) and an sRGB PNG preview next to it.")
    r.add_argument("scene", nargs="?", metavar="SCENE", help="scene file (.py with build()); omit for the demo")
    r.add_argument("-o", "--output", default="demo.exr", metavar="OUT.exr", help="output EXR (default: demo.exr)")
    r.add_argument("--spp", type=int, default=DEMO_SPP, metavar="N", help=f"samples per pixel (default {DEMO_SPP})")
    r.add_argument("--res", type=_parse_res, default=_parse_res(DEMO_RES), metavar="WxH",
                   help=f"resolution (default {DEMO_RES})")
    r.add_argument("--threads", type=int, default=0, metavar="N", help="worker threads (default: all cores)")
    r.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default 0)")
    r.add_argument("--time-limit", type=float, default=0.0, metavar="T",
                   help="stop after T seconds, at the end of a progressive pass (default: no limit)")
    r.add_argument("--max-depth", type=int, default=16, metavar="D", help="maximum path depth (default 16)")
    r.add_argument("--rr-depth", type=int, default=4, metavar="N",
                   help="diffuse bounces before Russian roulette may end a path (default 4; "
                        "above the diffuse budget: no roulette)")
    r.add_argument("--light-aa", type=int, default=4, metavar="E",
                   help="light antialiasing: extra camera rays per sample, gathering only the lights "
                        "seen directly, in pixels where a probe finds their edges (default 4; 0 = off)")
    r.add_argument("--no-path-lanes", action="store_true",
                   help="trace one path at a time, not a pixel's paths 8 at a time in vector lanes (the "
                        "lanes run on scenes of Lambert meshes and triangle lights; same image)")
    r.add_argument("--clamp", type=float, default=None, metavar="C",
                   help=f"clamp indirect sample luminance to C; 0 = off (default: off, or {DEMO_CLAMP:g} "
                        "for the demo scene, which tames its glass caustics)")
    r.add_argument("--sampler", choices=["zsobol", "sobol", "independent"], default="zsobol",
                   help="sample generator: Owen-scrambled Sobol' with neighbouring pixels sharing one "
                        "sequence in Morton order, blue-noise error (zsobol, default); the same per pixel "
                        "(sobol); PCG32 streams (independent)")
    r.add_argument("--reconstruction", choices=["splat", "filter_importance"], default="splat",
                   help="pixel reconstruction: splat each sample into the pixels its filter reaches "
                        "(default), or filter importance sampling (one pixel per sample, uncorrelated noise)")
    r.add_argument("--light-sampler", choices=["tree", "power"], default="tree",
                   help="light choice of next-event estimation: a light tree, by each light's bound at the "
                        "shading point (default; used from 16 lights), or in proportion to power")
    r.add_argument("--exposure", type=float, default=0.0, metavar="EV", help="preview exposure in stops")
    r.add_argument("--no-preview", action="store_true", help="do not write the PNG preview")
    r.add_argument("--no-aovs", action="store_true",
                   help="beauty only: skip the albedo, normal and depth AOVs (the EXR holds RGBA; a little faster)")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    return p


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.version:
        from . import __version__, build_info
        print(f"kauri {__version__} ({build_info['compiler']}, -march={build_info['march']}, "
              f"profile-guided: {build_info['pgo']}; path lanes: {build_info['path_lanes']}; "
              f"cores: {', '.join(build_info['cores'])})")
        return 0
    if args.command == "render":
        if args.spp <= 0:
            parser.error("--spp must be > 0")
        if args.threads < 0:
            parser.error("--threads must be >= 0")
        if not 0 <= args.light_aa <= 64:
            parser.error("--light-aa must be in [0, 64] (extra camera rays per sample)")
        return _cmd_render(args)
    parser.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
