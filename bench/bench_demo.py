#!/usr/bin/env python3
"""Benchmark: the built-in demo scene at a fixed resolution and spp.

Prints wall time, samples/s, rays/s and peak memory, best of N runs. Peer renderers
(Mitsuba 3, pbrt-v4) are compared side by side in the benchmark suite of a later issue.
"""
import argparse
import platform
import os
import time

import kauri
from kauri import demo


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--res", default="256x256", help="resolution WxH (default 256x256)")
    p.add_argument("--spp", type=int, default=32, help="samples per pixel (default 32)")
    p.add_argument("--runs", type=int, default=3, help="repetitions; the best is reported (default 3)")
    p.add_argument("--threads", type=int, default=0, help="threads (default: all cores)")
    args = p.parse_args()
    w, h = (int(v) for v in args.res.split("x"))
    scene = demo.build()
    kauri.render(scene, spp=1, resolution=(16, 16))  # warm-up: page in tables, start threads
    results = []
    for _ in range(args.runs):
        t0 = time.perf_counter()
        out = kauri.render(scene, spp=args.spp, resolution=(w, h), threads=args.threads, seed=1)
        wall = time.perf_counter() - t0
        results.append((wall, out.stats))
    wall, st = min(results, key=lambda r: r[0])
    print(f"kauri {kauri.__version__} demo scene, {w}x{h}, {args.spp} spp, "
          f"{args.threads or os.cpu_count()} threads, {platform.processor() or platform.machine()}")
    print(f"  wall time      {wall:8.3f} s   (best of {args.runs}; render loop {st['seconds']:.3f} s)")
    print(f"  samples/s      {st['samples'] / wall / 1e6:8.3f} M")
    print(f"  rays/s         {st['rays'] / wall / 1e6:8.3f} M   ({st['rays'] / st['samples']:.2f} rays per sample)")
    print(f"  peak memory    {st['peak_rss_bytes'] / 2**20:8.1f} MiB")


if __name__ == "__main__":
    main()
