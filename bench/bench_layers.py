#!/usr/bin/env python3
"""Benchmark: the cost of layered materials.

1. Runs the C++ micro-benchmark (build/*/kauri_bench_layers): ns per build_bsdf / eval /
   sample / pdf for 1-, 3- and 6-lobe stacks.
2. Renders one palette-like scene (a row of six spheres on a floor, environment + sun)
   through the Python API with the spheres' materials
     single   every sphere a single Lambert lobe,
     base     every sphere the bottom lobe of its stack alone (separates the cost of
              layering from that of a different lobe type),
     layered  clear coat over gold, water film over concrete, car paint, velvet,
              a 5-lobe leaf and a 6-lobe stack,
   at the same resolution, spp, seed and threads, best of N runs; prints wall time and
   samples/s of each and the ratios against layered.
"""
import argparse
import glob
import os
import platform
import subprocess
import sys
import time

import numpy as np

import kauri

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def find_cpp_bench():
    found = [p for p in glob.glob(os.path.join(ROOT, "build", "*", "kauri_bench_layers")) if os.access(p, os.X_OK)]
    return max(found, key=os.path.getmtime) if found else None


def run_cpp(iterations):
    exe = find_cpp_bench()
    if exe is None:
        print("C++ benchmark: build/*/kauri_bench_layers not found; build it with\n"
              "  cmake build/<wheel-tag> && ninja -C build/<wheel-tag> kauri_bench_layers\n"
              "(or `make build`, with KAURI_BUILD_BENCH=ON, the default)")
        return False
    print(f"C++ benchmark: {os.path.relpath(exe, ROOT)}")
    cmd = [exe] + (["--iterations", str(iterations)] if iterations else [])
    sys.stdout.flush()
    return subprocess.run(cmd).returncode == 0


# ---- the scene

def layered_materials():
    """(layered material, its bottom lobe alone) for each sphere, left to right."""
    out = []
    gold = kauri.Conductor(metal="Au", roughness=0.3)
    m = kauri.Material("clearcoat_gold")
    m.add_lobe("clear", kauri.Dielectric(ior=1.5)).add_lobe("gold", gold)
    m.combine("stack", "coat", "clear", "gold")
    out.append((m, kauri.Conductor(metal="Au", roughness=0.3, name="gold")))

    concrete = kauri.Lambert(albedo=(0.45, 0.43, 0.4))
    m = kauri.Material("wet_concrete", ior_accumulation=True, roughness_accumulation=True)
    m.add_lobe("water", kauri.Dielectric(ior=1.33), weight=0.8).add_lobe("concrete", concrete)
    m.combine("stack", "coat", "water", "concrete")
    out.append((m, kauri.Lambert(albedo=(0.45, 0.43, 0.4), name="concrete")))

    m = kauri.Material("car_paint")
    m.add_lobe("clear", kauri.Dielectric(ior=1.5))
    m.add_lobe("flakes", kauri.Conductor(metal="Al", roughness=0.4), weight=0.3)
    m.add_lobe("paint", kauri.Lambert(albedo=(0.6, 0.05, 0.04)), weight=0.7)
    m.combine("base", "mix", "flakes", "paint").combine("stack", "coat", "clear", "base")
    out.append((m, kauri.Lambert(albedo=(0.6, 0.05, 0.04), name="paint")))

    m = kauri.Material("velvet")
    m.add_lobe("fuzz", kauri.Sheen(color=(0.9, 0.6, 0.9), roughness=0.5))
    m.add_lobe("cloth", kauri.Lambert(albedo=(0.25, 0.05, 0.3)))
    m.combine("stack", "coat", "fuzz", "cloth")
    out.append((m, kauri.Lambert(albedo=(0.25, 0.05, 0.3), name="cloth")))

    m = kauri.Material("leaf", roughness_accumulation=True)
    m.add_lobe("fuzz", kauri.Sheen(color=(0.8, 0.9, 0.8), roughness=0.3), weight=0.2)
    m.add_lobe("cuticle", kauri.RoughDielectric(ior=1.45, roughness=0.3))
    m.add_lobe("dew", kauri.ThinDielectric(ior=1.33), weight=0.15)
    m.add_lobe("mesophyll", kauri.Lambert(albedo=(0.1, 0.35, 0.05)), weight=0.6)
    m.add_lobe("translucency", kauri.DiffuseTransmission(transmittance=(0.2, 0.5, 0.05)), weight=0.4)
    m.combine("body", "mix", "mesophyll", "translucency").combine("wet", "blend", "dew", "body")
    m.combine("waxed", "coat", "cuticle", "wet").combine("stack", "coat", "fuzz", "waxed")
    out.append((m, kauri.Lambert(albedo=(0.1, 0.35, 0.05), name="mesophyll")))

    m = kauri.Material("stack6", ior_accumulation=True, roughness_accumulation=True)
    m.add_lobe("fuzz", kauri.Sheen(color=(0.9, 0.9, 0.8), roughness=0.4), weight=0.5)
    m.add_lobe("clear", kauri.Dielectric(ior=1.45))
    m.add_lobe("copper", kauri.Conductor(metal="Cu", roughness=0.3), weight=0.3)
    m.add_lobe("diffuse", kauri.Lambert(albedo=(0.3, 0.5, 0.2)), weight=0.5)
    m.add_lobe("translucent", kauri.DiffuseTransmission(transmittance=(0.4, 0.6, 0.2)), weight=0.3)
    m.add_lobe("frosted", kauri.RoughDielectric(ior=1.33, roughness=0.25), weight=0.2)
    m.combine("body", "mix", "diffuse", "translucent", "frosted").combine("base", "blend", "copper", "body")
    m.combine("varnished", "coat", "clear", "base").combine("stack", "coat", "fuzz", "varnished")
    out.append((m, kauri.Lambert(albedo=(0.3, 0.5, 0.2), name="diffuse")))
    return out


SINGLE_ALBEDOS = [(0.8, 0.6, 0.2), (0.45, 0.43, 0.4), (0.6, 0.05, 0.04), (0.25, 0.05, 0.3), (0.1, 0.35, 0.05),
                  (0.3, 0.5, 0.2)]


def build_scene(variant):
    s = kauri.Scene()
    P = np.array([(-20, 0, 20), (20, 0, 20), (20, 0, -20), (-20, 0, -20)], dtype=np.float32)
    s.add_mesh(P, np.array([[0, 1, 2, 3]], dtype=np.uint32), material=kauri.Lambert(albedo=(0.5, 0.5, 0.5),
               name="floor"), name="floor")
    mats = layered_materials()
    for i in range(6):
        if variant == "single":
            mat = kauri.Lambert(albedo=SINGLE_ALBEDOS[i], name=f"lambert{i}")
        elif variant == "base":
            mat = mats[i][1]
        else:
            mat = mats[i][0]
        s.add_sphere(center=(-2.5 + i, 0.45, 0), radius=0.45, material=mat, name=f"sphere{i}")
    s.add_environment(color=(0.55, 0.7, 1.0), intensity=0.6)
    s.add_distant_light(direction=(-0.4, -1.0, -0.6), angle=0.53, color=(1.0, 0.95, 0.85), intensity=3.0,
                        name="sun")
    s.set_camera(eye=(0, 1.8, 7.0), target=(0, 0.4, 0), fov=50)
    return s


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smaller renders and fewer C++ iterations (a few seconds)")
    p.add_argument("--res", default=None, help="resolution WxH (default 320x180; --quick 160x90)")
    p.add_argument("--spp", type=int, default=None, help="samples per pixel (default 16; --quick 4)")
    p.add_argument("--runs", type=int, default=3, help="render repetitions; the best is reported (default 3)")
    p.add_argument("--threads", type=int, default=0, help="render threads (default: all cores)")
    p.add_argument("--iterations", type=int, default=None,
                   help="C++ benchmark calls per measurement (default: its own, 100000; --quick 20000)")
    p.add_argument("--skip-cpp", action="store_true", help="only the render comparison")
    args = p.parse_args()
    res = args.res or ("160x90" if args.quick else "320x180")
    spp = args.spp or (4 if args.quick else 16)
    iterations = args.iterations or (20000 if args.quick else 0)
    w, h = (int(v) for v in res.split("x"))

    ok = True
    if not args.skip_cpp:
        ok = run_cpp(iterations)
        print()

    scenes = {v: build_scene(v) for v in ("single", "base", "layered")}
    for s in scenes.values():
        kauri.render(s, spp=1, resolution=(16, 16), threads=args.threads)  # warm-up
    # Runs are interleaved across variants, so load from other processes spoils one
    # run of each rather than all runs of one.
    results = {}
    for _ in range(args.runs):
        for v, s in scenes.items():
            t0 = time.perf_counter()
            out = kauri.render(s, spp=spp, resolution=(w, h), threads=args.threads, seed=1)
            wall = time.perf_counter() - t0
            if v not in results or wall < results[v][0]:
                results[v] = (wall, out.stats)
    print(f"kauri {kauri.__version__} layered-material render overhead: 6 spheres on a floor, environment + sun, "
          f"{w}x{h}, {spp} spp, seed 1, {args.threads or os.cpu_count()} threads, best of {args.runs}, "
          f"{platform.processor() or platform.machine()}")
    labels = {"single": "single (lambert)", "base": "single (base lobe)", "layered": "layered (2-6 lobes)"}
    print(f"  {'materials':<20} {'wall s':>8} {'loop s':>8} {'Msamples/s':>11} {'rays/sample':>12} {'layouts':>8}")
    for v, (wall, st) in results.items():
        print(f"  {labels[v]:<20} {wall:8.3f} {st['seconds']:8.3f} {st['samples'] / wall / 1e6:11.3f} "
              f"{st['rays'] / st['samples']:12.2f} {st['layer_layouts']:8d}")
    print("  (wall: the whole kauri.render call; loop: its render loop; samples/s from wall)")
    lay = results["layered"][0]
    print(f"  layered / single (lambert)   wall-time ratio {lay / results['single'][0]:.2f}x")
    print(f"  layered / single (base lobe) wall-time ratio {lay / results['base'][0]:.2f}x")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
