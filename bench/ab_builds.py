"""A/B timing of two kauri builds on a noisy machine: paired renders, reported as ratios.

    python bench/ab_builds.py --a build/a --b build/b [--scene cornell] [--rounds 10]

`--a` and `--b` are CMake build folders (their `_core*.so` is used with this checkout's
`python/kauri`) or package folders that hold a `kauri/` package. Each side runs in its own
Python process that imports kauri from that folder alone (the editable install's finder is
dropped, and KAURI_ISA=base unless set), renders one bench scene on one thread and prints
each render's CPU time.

Why paired: on the 2-core VMs these sessions run on, a build's render time drifts by
±30% within minutes (other tenants of the host), far more than the few percent a change is
worth. Here A and B run *at the same moments*, one per core (pinned with taskset, cores
swapped every round; both load and warm up, then start their timed renders together),
and the statistic is the per-render ratio B / A of renders that ran side by side, so drift
that hits both cores cancels. Even so, A against A gave medians 0.995 and 1.03 with
quartiles as wide as 0.75-1.30 (30 pairs each) on the Xeon of docs/benchmarks.md: read
the median of 30 or more pairs, run A against A first to see the machine's spread that
day, and run both orders (--a X --b Y, then --a Y --b X).

Instruction counts (callgrind, docs/developing.md) are exact but miss latency; this tool
measures time, for changes that move latency rather than instruction counts.
"""
from __future__ import annotations

import argparse
import glob
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENES = ("cornell", "textured", "glossy", "hangar", "envmap", "displaced")

# The worker: imports kauri from argv[1] only, renders a bench scene, prints CPU seconds per render.
WORKER = r"""
import os, sys, time
pkg, bench, name, spp, res, reps = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
sys.meta_path = [f for f in sys.meta_path if "Redirecting" not in type(f).__name__ and "editable" not in type(f).__name__.lower()]
sys.path[:0] = [pkg, bench]
import kauri
if not os.path.abspath(kauri.__file__).startswith(os.path.abspath(pkg)):
    sys.exit(f"kauri imported from {kauri.__file__}, not from {pkg}")
import importlib, peers
desc = importlib.import_module("scenes." + name).describe()
scene = peers.kauri_scene(desc)
kauri.render(scene, spp=4, resolution=(res, res), seed=0, aovs=False, threads=1, **peers.KAURI_PATH_LIMITS)
print("ready", flush=True)
sys.stdin.readline()  # both sides start their timed renders together
for r in range(reps):
    t = time.process_time()
    kauri.render(scene, spp=spp, resolution=(res, res), seed=r + 1, aovs=False, threads=1, **peers.KAURI_PATH_LIMITS)
    print(time.process_time() - t, flush=True)
"""


def package_dir(path: str, tmp: str, tag: str) -> str:
    """A folder holding a `kauri` package for `path`: the folder itself when it has one,
    else this checkout's python/kauri plus the build folder's compiled core(s)."""
    if os.path.isdir(os.path.join(path, "kauri")):
        return path
    cores = glob.glob(os.path.join(path, "_core*.so"))
    if not cores:
        raise SystemExit(f"{path}: neither a package folder (with kauri/) nor a build folder (with _core*.so)")
    dest = os.path.join(tmp, tag)
    shutil.copytree(os.path.join(ROOT, "python", "kauri"), os.path.join(dest, "kauri"))
    for so in cores:
        shutil.copy2(so, os.path.join(dest, "kauri"))
    return dest


def worker_cmd(cpu: str, pkg: str, args, worker: str) -> list[str]:
    cmd = [sys.executable, worker, pkg, HERE, args.scene, str(args.spp), str(args.res), str(args.renders)]
    return (["taskset", "-c", cpu] if shutil.which("taskset") else []) + cmd


def paired_ratios(times_a: list[float], times_b: list[float]) -> list[float]:
    """B / A of the renders that ran side by side (index by index)."""
    if len(times_a) != len(times_b):
        raise ValueError("both sides must report the same number of renders")
    return [b / a for a, b in zip(times_a, times_b) if a > 0]


def summary(ratios: list[float]) -> str:
    if len(ratios) < 4:
        return f"median {statistics.median(ratios):.3f} (n={len(ratios)})"
    q = statistics.quantiles(ratios, n=4)
    return f"median {statistics.median(ratios):.3f}, quartiles {q[0]:.3f}-{q[2]:.3f}, n={len(ratios)}"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a", required=True, help="baseline: build folder or package folder")
    p.add_argument("--b", required=True, help="candidate: build folder or package folder")
    p.add_argument("--scene", default="cornell", choices=SCENES)
    p.add_argument("--rounds", type=int, default=10, help="rounds of side-by-side renders (default 10)")
    p.add_argument("--renders", type=int, default=3, help="renders per side per round (default 3)")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--res", type=int, default=128)
    args = p.parse_args(argv)
    if min(args.rounds, args.renders, args.spp, args.res) < 1:
        p.error("--rounds, --renders, --spp and --res must be at least 1")
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else [0, 1]
    if len(cpus) < 2:
        p.error("needs two CPUs: A and B run side by side")
    with tempfile.TemporaryDirectory() as tmp:
        worker = os.path.join(tmp, "worker.py")
        with open(worker, "w") as f:
            f.write(WORKER)
        pa, pb = package_dir(args.a, tmp, "a"), package_dir(args.b, tmp, "b")
        env = dict(os.environ, KAURI_ISA=os.environ.get("KAURI_ISA", "base"))
        ta, tb = [], []
        for r in range(args.rounds):
            ca, cb = (str(cpus[0]), str(cpus[1])) if r % 2 == 0 else (str(cpus[1]), str(cpus[0]))
            procs = [subprocess.Popen(worker_cmd(c, pkg, args, worker), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True, env=env) for c, pkg in ((ca, pa), (cb, pb))]
            # Both import kauri, build the scene and warm up, then start timing together:
            # the side that loads faster would otherwise render its first frames alone.
            for proc in procs:
                proc.stdout.readline()  # "ready" (or "" if it failed; communicate() reports it)
            outs = [proc.communicate("go\n") for proc in procs]
            for proc, (out, err), side in zip(procs, outs, "AB"):
                if proc.returncode:
                    raise SystemExit(f"side {side} failed:\n{err[-2000:]}")
            ra, rb = ([float(x) for x in out.split()] for out, _ in outs)
            ta += ra
            tb += rb
            print(f"round {r + 1}/{args.rounds}: B/A {summary(paired_ratios(ta, tb))}", file=sys.stderr, flush=True)
    ratios = paired_ratios(ta, tb)
    print(f"{args.scene}, {args.res}x{args.res}, {args.spp} spp, one thread per side: "
          f"A median {statistics.median(ta):.3f} s, B median {statistics.median(tb):.3f} s; "
          f"B/A side by side: {summary(ratios)} (< 1: B is faster)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
