#!/usr/bin/env python3
"""Benchmark: how much of kauri's noise is colour noise (its spectral transport at 4
wavelengths a path) against Mitsuba 3's RGB variant, which has none.

Renders three versions of the Cornell box of bench/scenes/cornell.py, K times each with
independent seeds, with kauri (its default sampler) and with Mitsuba's `llvm_ad_rgb` (the
`multijitter` sampler of the suite's speed section), the same spp, filter, resolution and
path limits as the suite, and prints the per-pixel variance between the K renders relative
to the pixel's mean (var / (mean² + 0.01), averaged over the image: the relMSE of one
render about its own mean, so no reference and no bias enter it) and kauri's / Mitsuba's:

  bench      the suite's box (white 0.73, red and green walls);
  grey       every wall 0.5 grey: a flat reflectance spectrum, so the wavelengths a path
             carries change nothing but the lamp's and the sensor's spectra;
  saturated  grey room, walls (0.9, 0.1, 0.1) and (0.1, 0.9, 0.1).

Where kauri's ratio rises from the grey box to the coloured ones, the difference is the
noise of estimating colours from a path's 4 wavelengths. Prints figures only; asserts
nothing.

  python bench/colour_noise.py [--renders 24] [--spp 64] [--res 64]
"""
import argparse
import os
import sys
import time

import numpy as np

BENCH = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, BENCH)

import suite  # noqa: E402  (its relMSE estimator, REL_EPS, Mitsuba sampler and LLVM set-up)
from scenes import cornell  # noqa: E402

GREY = (0.5, 0.5, 0.5)


def box(kind):
    """The Cornell box description with its walls recoloured for `kind`."""
    desc = cornell.describe()
    walls = {"bench": {}, "grey": {"left": GREY, "right": GREY, "white": GREY},
             "saturated": {"left": (0.9, 0.1, 0.1), "right": (0.1, 0.9, 0.1), "white": GREY}}[kind]
    for shape in desc["shapes"]:
        if "diffuse" not in shape:
            continue
        key = shape["name"] if shape["name"] in ("left", "right") else "white"
        shape["diffuse"] = walls.get(key, shape["diffuse"])
    desc["name"] = f"cornell_{kind}"
    return desc


def relative_variance(images):
    """Mean over pixels and channels of the variance between renders / (mean² + REL_EPS):
    the suite's relMSE estimator with the renders' own mean as the reference."""
    stack = np.stack(images)
    return suite.relmse_from_runs(stack, stack.mean(axis=0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--renders", type=int, default=24, help="independent renders per renderer and box (>= 2)")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel (a square, for Mitsuba's multijitter)")
    ap.add_argument("--res", type=int, default=64, help="image width and height")
    args = ap.parse_args(argv)
    if args.renders < 2:
        ap.error("--renders: at least 2 (a variance needs two renders)")
    if args.spp < 1 or round(args.spp ** 0.5) ** 2 != args.spp:
        ap.error(f"--spp: expected a square number (Mitsuba's multijitter sampler rounds others up), got {args.spp}")
    if args.res < 1:
        ap.error(f"--res: expected a positive image size, got {args.res}")
    suite.setup_llvm_env()
    import peers

    res = (args.res, args.res)
    print(f"Cornell box variants, {args.res}x{args.res}, {args.spp} spp, {args.renders} renders each; "
          f"relative variance per pixel (lower is better)")
    print(f"{'box':<10} {'kauri':>11} {'llvm_ad_rgb':>12} {'kauri/mitsuba':>14} {'mean k/m':>9}")
    for kind in ("grey", "bench", "saturated"):
        desc = box(kind)
        t0 = time.perf_counter()
        k = [peers.render_kauri(desc, spp=args.spp, resolution=res, seed=s) for s in range(args.renders)]
        m = [peers.render_mitsuba(desc, "llvm_ad_rgb", spp=args.spp, resolution=res, seed=s,
                                  sampler=suite.SPEED_MITSUBA_SAMPLER) for s in range(args.renders)]
        vk, vm = relative_variance(k), relative_variance(m)
        mean_ratio = float(np.mean(k) / np.mean(m))
        print(f"{kind:<10} {vk:11.4g} {vm:12.4g} {vk / vm:14.3f} {mean_ratio:9.4f}   "
              f"({time.perf_counter() - t0:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
