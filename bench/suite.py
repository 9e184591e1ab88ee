#!/usr/bin/env python3
"""kauri benchmark suite (issue 4): kauri against Mitsuba 3 and Blender's Cycles on the scenes
of bench/scenes.

Renders every scene with kauri and with Mitsuba 3 in the same run, prints the tables and
writes a markdown report, the raw numbers (results.json) and PNG plots to bench/results/.

Sections
  1 agreement  kauri vs Mitsuba scalar_spectral: relative difference of the image mean per
               channel, per-channel relMSE between the two mean images (with the level that
               noise alone would give), and a z-test on 4x4 block means (|z| < 5 passes).
               kauri vs Cycles (an RGB renderer): the image means per channel, within 1.5%
               (3% with measured metals, which Cycles gets as RGB).
  2 speed      speed at equal quality: kauri, Mitsuba scalar_rgb, scalar_spectral,
               llvm_ad_rgb, llvm_ad_spectral, Cycles over an spp ladder. Error = relMSE of each
               renderer against its OWN expected image (its noise; bias is section 1),
               estimated from independent renders, per pixel and over 4x4-pixel blocks;
               efficiency = relMSE x wall time; time to reach kauri's top-rung error and
               the ratio time_peer / time_kauri (> 1: kauri is faster).
  3 replay     closeness to the limit: kauri's rays/s while rendering against Embree's
               alone on the same recorded rays (kauri.ray_replay), when the build has it.
  4 memory     peak resident memory of every renderer per scene, each render in its own
               subprocess, and the baseline of a subprocess that only imports the renderer
               and builds the scene.

Every renderer runs with the same thread count (--threads; kauri.render(threads=N) and
drjit.set_thread_count(N) for Mitsuba, render.threads = N for Cycles, checked by the CPU-time /
wall-time ratio). Cycles runs in its own Python (bpy pins NumPy 1.x): scripts/setup_cycles
installs it (make test does), --cycles-python names another, --no-cycles leaves it out.
Default (full): agreement 64x64, 128 spp, 16 renders; speed 64x64, spp 4/16/64/256,
8 timed renders per rung; memory 64x64, 256 spp. --quick: agreement 32x32, 64 spp, 10
renders; speed 32x32, spp 4/16/64, 6 renders; memory 32x32, 64 spp (every section, under
5 minutes on 2 cores); --quick leaves out the million-triangle 'displaced' scene unless
--scenes names it.
Outputs (written atomically): report.md, results.json, speed_<scene>.png, speed_all.png,
agreement_<scene>.png.
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import glob
import importlib
import json
import math
import os
import platform
import subprocess
import sys
import time
import types

# NumPy's OpenBLAS starts a worker per core whose threads spin after any BLAS call; in a
# profile of a timed kauri render they took 1.3% of the samples, CPU the renderers share.
# The suite needs no parallel BLAS (set before NumPy loads; workers inherit it).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

BENCH = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(BENCH)
if BENCH not in sys.path:
    sys.path.insert(0, BENCH)

from procinfo import vmhwm_kib  # noqa: E402


def _load_scene(name):
    module = importlib.import_module(f"scenes.{name}")
    if not callable(getattr(module, "describe", None)):
        raise ImportError(f"bench/scenes/{name}.py has no describe()")
    return module


# The scenes of the suite: one line per bench/scenes module with a describe().
SCENES = {
    "cornell": _load_scene("cornell"),
    "glossy": _load_scene("glossy"),
    "hangar": _load_scene("hangar"),
    "envmap": _load_scene("envmap"),
    "textured": _load_scene("textured"),
    "displaced": _load_scene("displaced"),
}
# Scenes --quick leaves out unless named in --scenes: a million triangles make every
# Mitsuba load (PLY parse and BVH build, about a second) longer than a quick render.
FULL_ONLY = {"displaced"}

KAURI = "kauri"
MITSUBA_VARIANTS = ("scalar_rgb", "scalar_spectral", "llvm_ad_rgb", "llvm_ad_spectral")
CYCLES = "cycles"
RENDERERS = (KAURI,) + MITSUBA_VARIANTS + (CYCLES,)
AGREEMENT_PEER = "scalar_spectral"
# Pixel filter of the agreement renders (peers.py): the box, which every renderer here
# reconstructs identically; Mitsuba's Gaussian is a piecewise-constant table of one.
AGREEMENT_FILTER = "box"
# Cycles renders in RGB: coloured interreflections differ from spectral transport by tenths
# of a percent, beyond noise at the agreement spp, and measured gold given as RGB η, k by up
# to ~2% in red; so its check is on the image means per channel, with these tolerances.
CYCLES_MEAN_TOL = 0.015
CYCLES_MEAN_TOL_METALS = 0.03
SECTIONS = ("agreement", "speed", "replay", "memory")
REL_EPS = 0.01   # relMSE denominator: ref^2 + REL_EPS keeps dark pixels from dominating
Z_PASS = 5.0     # block z-test threshold (as tests/python/test_peer_agreement.py)
#: Relative difference a block may show beyond noise: the renderers' RGB-to-spectrum fits.
#: A block that sees only an environment image has almost no noise in kauri, which adds
#: the image's colours as given where the camera sees it; Mitsuba's spectral variant adds
#: its fitted spectra, 0.08-0.19% off the bench sky's colours (scalar_rgb: within 0.005%).
FIT_FLOOR = 0.002


def cycles_tolerance(desc):
    """Tolerance of kauri vs Cycles image means for a scene description."""
    return CYCLES_MEAN_TOL_METALS if any("conductor" in sh for sh in desc["shapes"]) else CYCLES_MEAN_TOL


@dataclasses.dataclass(frozen=True)
class Config:
    agree_res: int      # square image side, section 1
    agree_spp: int
    agree_runs: int     # independent renders per renderer
    speed_res: int      # section 2
    ladder: tuple       # spp rungs
    speed_runs: int     # independent (timed) renders per rung, after one warm-up
    ref_spp: int        # kauri reference (only in the relMSE denominator)
    fit_min_spp: int    # rungs used for the efficiency fit
    mem_res: int        # section 4: one render per renderer and scene
    mem_spp: int


QUICK = Config(agree_res=32, agree_spp=64, agree_runs=10, speed_res=32, ladder=(4, 16, 64), speed_runs=6,
               ref_spp=1024, fit_min_spp=16, mem_res=32, mem_spp=64)
FULL = Config(agree_res=64, agree_spp=128, agree_runs=16, speed_res=64, ladder=(4, 16, 64, 256), speed_runs=8,
              ref_spp=4096, fit_min_spp=16, mem_res=64, mem_spp=256)


# ---------------------------------------------------------------------------------------
# Pure functions (tested by tests/python/test_bench_suite.py)

def relmse_from_runs(runs, ref, eps=REL_EPS):
    """relMSE of one render against the renderer's own expected image, from K independent
    renders `runs` (K, H, W, C): mean over pixels and channels of s^2 / (ref^2 + eps), with
    s^2 the unbiased (ddof = 1) sample variance over the K renders, an unbiased estimate of
    E[(I - E[I])^2]. `ref` (H, W, C) only scales the error (a converged image)."""
    runs = np.asarray(runs, np.float64)
    if runs.shape[0] < 2:
        raise ValueError("relmse_from_runs: need at least 2 independent renders")
    var = runs.var(axis=0, ddof=1)
    return float(np.mean(var / (np.asarray(ref, np.float64) ** 2 + eps)))


def efficiency(spps, relmses, times, min_spp=16):
    """Work-normalised error c = relMSE x time. With relMSE proportional to 1/t, c is constant;
    it is fitted as the geometric mean of relMSE * t over the rungs with spp >= min_spp
    (at lower spp fixed per-call costs dominate the time). Smaller is better."""
    vals = [e * t for s, e, t in zip(spps, relmses, times) if s >= min_spp and e > 0 and t > 0]
    if not vals:
        raise ValueError("efficiency: no rung with spp >= min_spp")
    return float(np.exp(np.mean(np.log(vals))))


def marginal_efficiency(spps, relmses, times):
    """Efficiency without the fixed per-call cost: the cost per sample from the top two rungs,
    (t_top - t_prev) / (spp_top - spp_prev), times spp_top, times the top rung's relMSE; and
    the per-call overhead t_top - spp_top * cost per sample (clamped to >= 0). For long renders
    (where a fixed scene sync or kernel launch per call no longer matters) this is the figure;
    the fitted c includes the overhead. Returns (c_marginal, overhead_s)."""
    if len(spps) < 2:
        raise ValueError("marginal_efficiency: need two rungs")
    (s0, s1), (t0, t1) = spps[-2:], times[-2:]
    per_sample = max((t1 - t0) / (s1 - s0), 1e-12)
    return float(relmses[-1] * per_sample * s1), float(max(0.0, t1 - s1 * per_sample))


def time_to_error(c, target):
    """Time to reach relMSE `target` for a renderer of efficiency c (relMSE = c / t)."""
    return c / target


def loglog_slope(times, relmses):
    """Least-squares slope of log relMSE against log time; -1 when relMSE is proportional to 1/t."""
    x, y = np.log(np.asarray(times, float)), np.log(np.asarray(relmses, float))
    if len(x) < 2:
        return float("nan")
    return float(np.polyfit(x, y, 1)[0])


def ratio_table(values, base=KAURI):
    """{scene: {renderer: t}} -> {scene: {renderer: t / t[base]}} for every renderer but base
    (> 1: base is faster). Scenes where base has no value are left out; None stays None."""
    out = {}
    for scene, row in values.items():
        b = row.get(base)
        if b is None or not b > 0:
            continue
        out[scene] = {r: (None if v is None else v / b) for r, v in row.items() if r != base}
    return out


def geometric_means(table):
    """Per-column geometric mean of a {scene: {renderer: ratio}} table (None skipped)."""
    cols = {}
    for row in table.values():
        for r, v in row.items():
            if v is not None and v > 0:
                cols.setdefault(r, []).append(math.log(v))
    return {r: math.exp(sum(v) / len(v)) for r, v in cols.items()}


def block_means(img, n=4, border=2):
    """Means over n x n blocks of the image without its `border` pixels (as in the peer
    test: at the image edge kauri and Mitsuba reconstruct differently). Works on (..., H, W, C)."""
    img = np.asarray(img, np.float64)
    img = img[..., border:img.shape[-3] - border, border:img.shape[-2] - border, :]
    h, w = img.shape[-3] // n * n, img.shape[-2] // n * n
    img = img[..., :h, :w, :]
    shp = img.shape[:-3] + (n, h // n, n, w // n, img.shape[-1])
    return img.reshape(shp).mean(axis=(-4, -2))


def block_z(k_runs, m_runs, n=4, border=2):
    """z-score per block and channel of the difference of the mean block values of two sets
    of independent renders (K, H, W, C), with standard errors from the runs, plus a floor of
    FIT_FLOOR of the block's mean spread over the Z_PASS standard errors: |z| < Z_PASS means
    |Δ| < Z_PASS·se + FIT_FLOOR·mean (as tests/python/test_peer_agreement.py bounds it)."""
    k, m = block_means(k_runs, n, border), block_means(m_runs, n, border)
    se = np.sqrt(k.var(0, ddof=1) / len(k) + m.var(0, ddof=1) / len(m))
    return (k.mean(0) - m.mean(0)) / np.maximum(se + FIT_FLOOR * np.abs(m.mean(0)) / Z_PASS, 1e-9)


def mean_rel_diff(a, b):
    """Per-channel relative difference of image means, (mean a - mean b) / mean b."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    ma, mb = a.reshape(-1, a.shape[-1]).mean(0), b.reshape(-1, b.shape[-1]).mean(0)
    return (ma - mb) / mb


def mean_rel_diff_se(a_runs, b_runs):
    """Standard error of mean_rel_diff(a_runs.mean(0), b_runs.mean(0)) from the spread of the
    per-render image means (K, H, W, C) -> (C,)."""
    a = np.asarray(a_runs, np.float64).reshape(len(a_runs), -1, np.shape(a_runs)[-1]).mean(1)
    b = np.asarray(b_runs, np.float64).reshape(len(b_runs), -1, np.shape(b_runs)[-1]).mean(1)
    return np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b)) / b.mean(0)


def relmse_between(a_runs, b_runs, eps=REL_EPS):
    """Per-channel relMSE between the mean images of two sets of independent renders, over
    the pixels given, with b's mean as reference: mean (A - B)^2 / (B^2 + eps). Also returns
    the value noise alone gives in expectation, mean (s_a^2/K_a + s_b^2/K_b) / (B^2 + eps)."""
    a_runs, b_runs = np.asarray(a_runs, np.float64), np.asarray(b_runs, np.float64)
    A, B = a_runs.mean(0), b_runs.mean(0)
    den = B ** 2 + eps
    rel = ((A - B) ** 2 / den).reshape(-1, A.shape[-1]).mean(0)
    noise = (a_runs.var(0, ddof=1) / len(a_runs) + b_runs.var(0, ddof=1) / len(b_runs)) / den
    return rel, noise.reshape(-1, A.shape[-1]).mean(0)


def md_table(headers, rows):
    """A markdown table (also readable as plain text)."""
    cells = [[str(h) for h in headers]] + [[str(c) for c in r] for r in rows]
    width = [max(len(r[i]) for r in cells) for i in range(len(headers))]
    fmt = lambda r: "| " + " | ".join(c.ljust(w) for c, w in zip(r, width)) + " |"
    return "\n".join([fmt(cells[0]), "|" + "|".join("-" * (w + 2) for w in width) + "|"]
                     + [fmt(r) for r in cells[1:]])


def fmt_g(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


# ---------------------------------------------------------------------------------------
# Environment: LLVM for Dr.Jit, thread count, machine description

def libllvm_path():
    """Path of Debian's libLLVM 19 (Dr.Jit's LLVM backend fails on LLVM 15: 'Cannot select:
    fminimum'), or None."""
    found = sorted(glob.glob("/usr/lib/*/libLLVM.so.19*") + glob.glob("/usr/lib/llvm-19/lib/libLLVM*.so*"))
    if found:
        return found[0]
    try:
        files = subprocess.run(["dpkg", "-L", "libllvm19"], capture_output=True, text=True).stdout.split()
    except OSError:
        return None
    files = [f for f in files if "/libLLVM" in f and ".so" in f and os.path.exists(f)]
    return files[0] if files else None


def setup_llvm_env():
    """Sets DRJIT_LIBLLVM_PATH (if unset) before mitsuba / drjit are imported."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"] + " (from the environment)"
    path = libllvm_path()
    if path:
        os.environ["DRJIT_LIBLLVM_PATH"] = path
        return path
    return "not found (apt-get install libllvm19); Dr.Jit picks its default"


def default_threads():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def vector_isa(flags_line=None):
    """The widest x86 vector extension the CPU reports ("AVX-512", "AVX2", "SSE" or, off
    x86 / without /proc/cpuinfo, the machine name): Dr.Jit's LLVM kernels are as wide as it
    allows, kauri's scalar code is not, so the speed ratios against the LLVM variants depend
    on it. `flags_line`: a /proc/cpuinfo "flags" line (tests)."""
    if flags_line is None:
        try:
            with open("/proc/cpuinfo") as f:
                flags_line = next((line for line in f if line.startswith("flags")), "")
        except OSError:
            flags_line = ""
    flags = set(flags_line.split(":", 1)[-1].split())
    if "avx512f" in flags:
        return "AVX-512"
    if "avx2" in flags:
        return "AVX2"
    if "sse2" in flags:
        return "SSE"
    return platform.machine()


def drjit_llvm_target():
    """(target CPU, vector lanes) of Dr.Jit's LLVM backend, or None. Read through Dr.Jit's
    C++ API (`jit_llvm_target_cpu`, `jit_llvm_vector_width` in libdrjit-core), which its
    Python bindings do not expose; valid once an LLVM variant has run in this process."""
    try:
        import ctypes
        import drjit
        lib = ctypes.CDLL(os.path.join(os.path.dirname(drjit.__file__), "libdrjit-core.so"))
        cpu, width = lib._Z19jit_llvm_target_cpuv, lib._Z21jit_llvm_vector_widthv
        cpu.restype, width.restype = ctypes.c_char_p, ctypes.c_uint32
        name, lanes = cpu(), int(width())
        return (name.decode() if name else "?", lanes) if lanes else None
    except (ImportError, OSError, AttributeError):
        return None


def mem_total_gib():
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal"):
                    return int(line.split()[1]) / 2 ** 20
    except OSError:
        pass
    return float("nan")


def versions():
    v = {"python": platform.python_version(), "numpy": np.__version__}
    try:
        v["commit"] = subprocess.run(["git", "-C", ROOT, "describe", "--always", "--dirty"], capture_output=True,
                                     text=True, timeout=10).stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        v["commit"] = "unknown"
    try:
        import kauri
        b = kauri.build_info
        v["kauri"] = (f"{kauri.__version__} ({b['compiler']}, -march={b['march']}, pgo={b['pgo']}, "
                      f"path lanes={b['path_lanes']})")
        v["kauri_march"] = b["march"]
        v["kauri_path_lanes"] = b["path_lanes"]
    except Exception as e:  # noqa: BLE001 - reported, not fatal here
        v["kauri"] = f"import failed: {e}"
    try:
        import drjit
        import mitsuba
        v["mitsuba"], v["drjit"] = mitsuba.__version__, drjit.__version__
    except Exception as e:  # noqa: BLE001
        v["mitsuba"] = f"not available: {e}"
    return v


def mitsuba_available():
    try:
        import mitsuba  # noqa: F401
        return True
    except Exception:  # noqa: BLE001
        return False


# ---------------------------------------------------------------------------------------
# Rendering through bench/peers.py with a thread count and a timer on the render call

@dataclasses.dataclass
class Call:
    wall: float          # seconds, the render call only (scene export / load not included)
    cpu: float           # process CPU seconds during the call (all threads)
    compile_s: float = 0.0   # Dr.Jit: codegen + LLVM backend time of kernels not in the memory cache
    disk_hit: bool = False   # Dr.Jit: some kernel came from the on-disk cache (~/.drjit)


# Pause before every timed render call (any renderer). Dr.Jit's worker threads keep spinning
# for some milliseconds after a kernel: a kauri render of the Cornell box at 16 spp (34 ms)
# started right after a Mitsuba render took 40-50 ms, with a Dr.Jit worker taking CPU time
# during it, and 34-35 ms after 20 ms or more of pause (bench/suite.py's interleaved rounds
# put some other renderer before nearly every render). Mitsuba's renders after kauri's were
# not slowed (TBB's workers do not spin that long). Applied to all renderers alike.
SETTLE_S = 0.05


def settle():
    """Lets the previous render's worker threads go idle (SETTLE_S)."""
    time.sleep(SETTLE_S)


class _RendererProxy:
    """Stands in for the kauri or mitsuba module while peers.render_kauri / render_mitsuba
    run: everything is forwarded to the real module except render(), which gets the suite's
    thread count (kauri) and is timed. So the scene export and the render settings are
    exactly those of peers.py, and only the render call is timed."""

    def __init__(self, module, on_render):
        self._module, self._on_render = module, on_render

    def __getattr__(self, name):
        return getattr(self._module, name)

    def render(self, *args, **kwargs):
        return self._on_render(self._module, *args, **kwargs)


class Renderers:
    """render(name, desc, spp, res, seed) -> (image (H, W, 3) float64, Call)."""

    def __init__(self, threads, cycles_python=None):
        self.threads = threads
        self.drjit_threads = None  # drjit.thread_count() after set_thread_count(threads)
        self._drjit_ready = False
        self.cycles_python = cycles_python
        self._cycles = None  # peers.CyclesPeer, started on the first Cycles render

    def close(self):
        if self._cycles is not None:
            _live_helpers.remove(self._cycles)
            self._cycles.close()
            self._cycles = None

    def cycles_version(self):
        return self._cycles.version if self._cycles is not None else None

    def _render_cycles(self, desc, spp, res, seed, pixel_filter):
        import peers
        if self._cycles is None:
            self._cycles = peers.CyclesPeer(self.cycles_python)
            _live_helpers.append(self._cycles)
        if desc["name"] not in SCENES:
            raise ValueError(f"Cycles renders the bench scenes by name; {desc['name']!r} is not one")
        settle()
        img, wall, cpu = self._cycles.render(desc, spp, (res, res), seed, self.threads, pixel_filter)
        return img, Call(wall, cpu)

    def _setup_drjit(self):
        if not self._drjit_ready:
            import drjit as dr
            dr.set_thread_count(self.threads)
            dr.set_flag(dr.JitFlag.KernelHistory, True)
            self.drjit_threads = dr.thread_count()
            self._drjit_ready = True

    def render(self, renderer, desc, spp, res, seed, pixel_filter="gaussian", mitsuba_sampler="independent"):
        import peers
        if renderer == CYCLES:
            return self._render_cycles(desc, spp, res, seed, pixel_filter)
        calls = []
        if renderer == KAURI:
            def timed(kauri_mod, *args, **kwargs):
                kwargs["threads"] = self.threads
                settle()
                t0, c0 = time.perf_counter(), time.process_time()
                out = kauri_mod.render(*args, **kwargs)
                calls.append(Call(time.perf_counter() - t0, time.process_time() - c0))
                return out
            real = peers.kauri
            peers.kauri = _RendererProxy(real, timed)
            try:
                img = peers.render_kauri(desc, spp, (res, res), seed, pixel_filter)
            finally:
                peers.kauri = real
        else:
            import drjit as dr
            import mitsuba
            self._setup_drjit()
            jit = renderer.startswith(("llvm", "cuda"))

            def timed(mi_mod, *args, **kwargs):
                if jit:
                    dr.sync_thread()
                    dr.kernel_history()  # clears the history
                settle()
                t0, c0 = time.perf_counter(), time.process_time()
                out = mi_mod.render(*args, **kwargs)
                if jit:
                    dr.eval(out)
                    dr.sync_thread()
                call = Call(time.perf_counter() - t0, time.process_time() - c0)
                if jit:
                    for k in dr.kernel_history():
                        if k.get("type") == dr.KernelType.JIT and not k.get("cache_hit", True):
                            call.compile_s += (k.get("codegen_time", 0.0) + k.get("backend_time", 0.0)) / 1000
                        call.disk_hit |= bool(k.get("cache_disk", False))
                calls.append(call)
                return out
            # peers.render_mitsuba does `import mitsuba as mi` inside: hand it the proxy.
            sys.modules["mitsuba"] = _RendererProxy(mitsuba, timed)
            try:
                img = peers.render_mitsuba(desc, renderer, spp, (res, res), seed, pixel_filter, mitsuba_sampler)
            finally:
                sys.modules["mitsuba"] = mitsuba
        if len(calls) != 1:
            raise RuntimeError(f"expected one render call from peers.py, saw {len(calls)}")
        return np.asarray(img, np.float64)[..., :3], calls[0]


# ---------------------------------------------------------------------------------------
# Progress, output files

class Progress:
    def __init__(self):
        self.t0 = time.perf_counter()

    def elapsed(self):
        return time.perf_counter() - self.t0

    def __call__(self, msg):
        print(f"[{self.elapsed():7.1f} s] {msg}", flush=True)


def write_atomic(path, data, mode="w"):
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, mode) as f:
        f.write(data)
    os.replace(tmp, path)


def save_figure(fig, path):
    tmp = f"{path}.tmp-{os.getpid()}"
    fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    os.replace(tmp, path)


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


class CpuMeter:
    """CPU time used on the machine by other processes while a section runs (from /proc/stat,
    minus this process and its children): timings taken under foreign load are slower."""

    def __init__(self):
        self.t0, self.busy0, self.mine0 = time.perf_counter(), self._busy(), self._mine()

    @staticmethod
    def _busy():
        try:
            with open("/proc/stat") as f:
                v = [int(x) for x in f.readline().split()[1:]]
            return (sum(v[:3]) + sum(v[5:8])) / os.sysconf("SC_CLK_TCK")  # user nice system irq softirq steal
        except (OSError, ValueError):
            return float("nan")

    @staticmethod
    def _mine():
        # A live Cycles server is a child not yet waited for: os.times() does not count it
        # until it exits, so its CPU time is read from /proc (else it would show as "other").
        t = os.times()
        live = sum(p.cpu_seconds() for p in _live_helpers)
        return t.user + t.system + t.children_user + t.children_system + _worker_cpu_s + live

    def stop(self):
        wall = time.perf_counter() - self.t0
        mine = self._mine() - self.mine0
        other = max(0.0, self._busy() - self.busy0 - mine)
        return {"wall_s": wall, "own_cores": mine / wall, "other_cores": other / wall}


def loadavg():
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "n/a"


# ---------------------------------------------------------------------------------------
# Subprocess workers: probing Mitsuba variants, memory

def _worker_main(args):
    """`suite.py --worker probe|memory ...`: runs in a fresh interpreter."""
    setup_llvm_env()
    renderer = args.renderer
    if renderer != KAURI:
        # peers.py imports kauri at module level; keep kauri's libraries out of Mitsuba's
        # memory figure (peers only uses kauri inside its kauri functions).
        sys.modules.setdefault("kauri", types.ModuleType("kauri"))
    import peers
    desc = SCENES[args.scene].describe()
    res, spp = args.res, args.spp
    if args.worker == "probe" or not args.baseline:
        img, call = Renderers(args.threads).render(renderer, desc, spp, res, seed=1)
        print(json.dumps({"mean": float(img.mean()), "wall": call.wall, "vmhwm_kib": vmhwm_kib()}))
        return 0
    # Baseline: import the renderer and build the scene, no render.
    if renderer == KAURI:
        scene = peers.to_kauri(desc)
    else:
        import drjit as dr
        import mitsuba as mi
        dr.set_thread_count(args.threads)
        mi.set_variant(renderer)
        scene = mi.load_dict(peers.to_mitsuba(desc, spp, (res, res)))
        dr.eval()
        dr.sync_thread()
    print(json.dumps({"built": type(scene).__name__, "vmhwm_kib": vmhwm_kib()}))
    return 0


# ru_maxrss of an exec'd child starts from the RSS of the process it was forked from (Linux
# carries the old address space's high-water mark over exec), so workers are not started
# from this process once it holds kauri and Mitsuba: a small launcher, started before either
# is imported, runs them and reports os.wait4's rusage.
_LAUNCHER_CODE = r"""
import json, os, subprocess, sys
for line in sys.stdin:
    cmd, cwd = json.loads(line)
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=cwd)
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    p.stdout.close()
    sys.stdout.write(json.dumps([p.returncode, out, ru.ru_maxrss, ru.ru_utime + ru.ru_stime]) + "\n")
    sys.stdout.flush()
"""
_launcher = None
_live_helpers = []  # long-lived helper processes (peers.CyclesPeer) whose CPU counts as ours
_cycles_python_arg = None  # --cycles-python, for the Cycles memory workers
_worker_cpu_s = 0.0  # CPU seconds of the workers (the launcher's children, not in os.times here)


def start_launcher():
    global _launcher
    if _launcher is None:
        _launcher = subprocess.Popen([sys.executable, "-c", _LAUNCHER_CODE], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True)
    return _launcher


def stop_launcher():
    global _launcher
    if _launcher is not None:
        _launcher.stdin.close()
        _launcher.wait()
        _launcher = None


def run_worker(worker, renderer, scene, res, spp, threads, baseline=False):
    """Runs a worker subprocess (through the launcher); returns (returncode, output text,
    peak RSS in KiB: ru_maxrss of the worker from os.wait4)."""
    if renderer == CYCLES:
        import peers
        cmd = [peers.cycles_python(_cycles_python_arg), os.path.join(BENCH, "cycles_peer.py"), "--scene", scene,
               "--res", str(res), "--spp", str(spp), "--threads", str(threads),
               "--metal-rgb", json.dumps(peers.metal_rgb(SCENES[scene].describe()))]
    else:
        cmd = [sys.executable, os.path.abspath(__file__), "--worker", worker, "--renderer", renderer, "--scene",
               scene, "--res", str(res), "--spp", str(spp), "--threads", str(threads)]
    cmd += ["--baseline"] if baseline else []
    launcher = start_launcher()
    launcher.stdin.write(json.dumps([cmd, ROOT]) + "\n")
    launcher.stdin.flush()
    line = launcher.stdout.readline()
    if not line:
        raise RuntimeError("the worker launcher died")
    global _worker_cpu_s
    rc, out, maxrss, cpu = json.loads(line)
    _worker_cpu_s += cpu
    return rc, out, maxrss


def _failure_reason(rc, text):
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    key = [line for line in lines if "error" in line.lower() or "exception" in line.lower()]
    why = (key[0] if key else (lines[-1] if lines else "no output"))[:200]
    sig = f"killed by signal {-rc}" if rc < 0 else f"exit status {rc}"
    return f"{sig}: {why}"


def probe_variants(variants, threads, log):
    """Mitsuba variants that render a small Cornell box in a subprocess (an LLVM that cannot
    compile Dr.Jit's kernels aborts the process, so this cannot be tried in-process)."""
    ok, skipped = [], {}
    for v in variants:
        rc, out, _ = run_worker("probe", v, "cornell", 8, 1, threads)
        if rc == 0:
            ok.append(v)
        else:
            skipped[v] = _failure_reason(rc, out)
            log(f"probe: Mitsuba {v} skipped ({skipped[v]})")
    return ok, skipped


def probe_cycles(rnd, log):
    """(True, None) when Cycles renders a tiny Cornell box, else (False, why)."""
    import peers
    if not peers.cycles_python(rnd.cycles_python):
        return False, "bpy is not installed (run scripts/setup_cycles, or pass --cycles-python)"
    try:
        rnd.render(CYCLES, SCENES["cornell"].describe(), 1, 8, seed=1)
        return True, None
    except Exception as e:  # noqa: BLE001 - reported in the tables
        rnd.close()
        return False, f"{type(e).__name__}: {e}"[:200]


# ---------------------------------------------------------------------------------------
# Section 1: agreement

def cycles_agreement(k, c, tol, b=2):
    """kauri runs k vs Cycles runs c (N, H, W, 3): relative difference of the interior image
    means per channel with standard errors, the largest 4x4-block |z| (information: RGB vs
    spectral differences exceed noise there) and pass = every |Δmean| < tol."""
    rel = mean_rel_diff(k[:, b:-b, b:-b].mean(0), c[:, b:-b, b:-b].mean(0))
    se = mean_rel_diff_se(k[:, b:-b, b:-b], c[:, b:-b, b:-b])
    return {"mean_rel_diff": rel.tolist(), "mean_rel_diff_se": se.tolist(), "tolerance": tol,
            "max_abs_z": float(np.abs(block_z(k, c)).max()), "pass": bool(np.all(np.abs(rel) < tol))}


def section_agreement(cfg, names, rnd, out_dir, log, cycles=False):
    res, spp, runs = cfg.agree_res, cfg.agree_spp, cfg.agree_runs
    data, rows, crows = {}, [], []
    for name in names:
        desc = SCENES[name].describe()
        sets = {}
        try:
            for r in (KAURI, AGREEMENT_PEER):
                log(f"agreement {name}: {r}, {runs} renders x {spp} spp at {res}x{res}")
                sets[r] = np.stack([rnd.render(r, desc, spp, res, seed=100 + s, pixel_filter=AGREEMENT_FILTER)[0]
                                    for s in range(runs)])
        except Exception as e:  # noqa: BLE001 - reported in the table
            log(f"agreement {name}: failed: {type(e).__name__}: {e}")
            data[name] = {"status": "failed", "reason": f"{type(e).__name__}: {e}"}
            rows.append([name, f"failed: {type(e).__name__}: {e}"[:80]] + [""] * 8)
            continue
        k, m = sets[KAURI], sets[AGREEMENT_PEER]
        if cycles:
            try:
                log(f"agreement {name}: {CYCLES}, {runs} renders x {spp} spp at {res}x{res}")
                c = np.stack([rnd.render(CYCLES, desc, spp, res, seed=100 + s, pixel_filter=AGREEMENT_FILTER)[0]
                              for s in range(runs)])
                ca = cycles_agreement(k, c, cycles_tolerance(desc))
                crows.append([name] + [f"{100 * v:+.2f} ± {100 * e:.2f}%" for v, e in
                                       zip(ca["mean_rel_diff"], ca["mean_rel_diff_se"])]
                             + [f"{ca['max_abs_z']:.1f}", f"{100 * ca['tolerance']:g}%",
                                "pass" if ca["pass"] else "FAIL"])
            except Exception as e:  # noqa: BLE001 - reported in the table
                log(f"agreement {name}: Cycles failed: {type(e).__name__}: {e}")
                ca = {"status": "failed", "reason": f"{type(e).__name__}: {e}"}
                crows.append([name, f"failed: {ca['reason']}"[:80], "", "", "", "", ""])
        z = block_z(k, m)
        zmax = float(np.abs(z).max())
        b = 2  # interior: the border is where the renderers reconstruct differently
        rel = mean_rel_diff(k[:, b:-b, b:-b].mean(0), m[:, b:-b, b:-b].mean(0))
        rel_se = mean_rel_diff_se(k[:, b:-b, b:-b], m[:, b:-b, b:-b])
        rmse, floor = relmse_between(k[:, b:-b, b:-b], m[:, b:-b, b:-b])
        data[name] = {"mean_rel_diff": rel.tolist(), "mean_rel_diff_se": rel_se.tolist(), "relmse": rmse.tolist(),
                      "relmse_noise": floor.tolist(), "max_abs_z": zmax, "z": z.tolist(), "pass": zmax < Z_PASS}
        if cycles:
            data[name][CYCLES] = ca
        rows.append([name] + [f"{100 * v:+.2f} ± {100 * e:.2f}%" for v, e in zip(rel, rel_se)]
                    + [f"{v:.2e}" for v in rmse]
                    + [f"{np.mean(floor):.2e}", f"{zmax:.2f}", "pass" if zmax < Z_PASS else "FAIL"])
        try:
            plot_agreement(name, k, m, z, os.path.join(out_dir, f"agreement_{name}.png"))
        except Exception as e:  # noqa: BLE001 - a plot must not stop the run
            log(f"agreement {name}: plot failed: {e}")
    headers = ["scene", "Δmean R", "Δmean G", "Δmean B", "relMSE R", "relMSE G", "relMSE B", "noise level",
               "max abs(z)", f"z-test: abs(z) < {Z_PASS:g}"]
    table = md_table(headers, rows)
    print("\n" + table + "\n", flush=True)
    md = [f"Configuration: {res}×{res} px, {spp} spp, {runs} independent renders per renderer "
          f"(seeds 100–{99 + runs}), kauri vs Mitsuba `{AGREEMENT_PEER}`, one-pixel box filter in both.",
          "",
          "The box is the one pixel filter the renderers reconstruct identically: Mitsuba 3 splats "
          "with a piecewise-constant table of its Gaussian (28% more weight 1.8 px out than the Gaussian, effective "
          "σ 0.512 px instead of 0.5), which next to a bright edge differs from kauri's exact Gaussian "
          "by more than noise (bench/peers.py). Transport is what this section compares.",
          "",
          "Δmean: (mean kauri − mean Mitsuba) / mean Mitsuba per channel over the interior "
          "(2-px border excluded), ± one standard error from the spread of the per-render means. relMSE: mean over interior pixels of (K̄ − M̄)² / (M̄² + 0.01) "
          "between the two mean images, per channel; 'noise level' is what independent noise alone "
          "gives in expectation (mean of (s²_K + s²_M) / K / (M̄² + 0.01) over channels): relMSE well "
          "above it is bias. max abs(z): the largest |z| over 4×4 interior blocks × 3 channels of the "
          "difference of block means, standard errors from the runs plus a floor of 0.2% of the block's "
          "mean (the renderers' RGB-to-spectrum fits: where kauri's camera sees an environment image it adds the "
          "image's colours as given, Mitsuba's spectral variant its fitted spectra), as "
          "tests/python/test_peer_agreement.py.",
          "", table, ""]
    md += [" ".join(f"[{n}](agreement_{n}.png)" for n in names if os.path.exists(
        os.path.join(out_dir, f"agreement_{n}.png"))), ""]
    if crows:
        ctable = md_table(["scene", "Δmean R", "Δmean G", "Δmean B", "max abs(z) (information)", "tolerance",
                           "abs(Δmean) < tolerance"], crows)
        print("\nkauri vs Cycles:\n" + ctable + "\n", flush=True)
        md += ["kauri vs Blender's Cycles (same renders of kauri, same seeds and spp): Δmean = (mean kauri − "
               "mean Cycles) / mean Cycles per channel over the interior. Cycles transports RGB, not spectra: "
               "coloured interreflections differ from spectral rendering by tenths of a percent, and "
               "gold given to it as RGB η and k by up to ~2% in red, beyond noise here; so the check is "
               f"|Δmean| per channel below {100 * CYCLES_MEAN_TOL:g}% ({100 * CYCLES_MEAN_TOL_METALS:g}% in "
               "scenes with measured metals), and the block z is information, not a test.",
               "", ctable, ""]
    return data, md


def plot_agreement(name, k, m, z, path):
    plt = _pyplot()
    K, M = k.mean(0), m.mean(0)
    se = np.sqrt(k.var(0, ddof=1) / len(k) + m.var(0, ddof=1) / len(m)).mean(-1)
    zpix = (K - M).mean(-1) / np.maximum(se, 1e-9)
    fig, ax = plt.subplots(1, 4, figsize=(13, 3.4))
    scale = max(np.percentile(K, 99.5), 1e-6)
    for a, img, title in ((ax[0], K, "kauri (mean)"), (ax[1], M, f"Mitsuba {AGREEMENT_PEER} (mean)")):
        a.imshow(np.clip(img / scale, 0, 1) ** (1 / 2.2), interpolation="nearest")
        a.set_title(title, fontsize=9)
    im = ax[2].imshow(zpix, cmap="RdBu_r", vmin=-5, vmax=5, interpolation="nearest")
    ax[2].set_title("per-pixel z (kauri − Mitsuba)", fontsize=9)
    fig.colorbar(im, ax=ax[2], fraction=0.046)
    zb = np.abs(np.asarray(z)).max(-1)
    im = ax[3].imshow(zb, cmap="magma", vmin=0, vmax=max(Z_PASS + 1, zb.max()), interpolation="nearest")
    ax[3].set_title("4×4 block max |z| (interior)", fontsize=9)
    fig.colorbar(im, ax=ax[3], fraction=0.046)
    for a in ax:
        a.set_xticks([])
        a.set_yticks([])
    fig.suptitle(f"{name}: agreement", fontsize=10)
    save_figure(fig, path)
    plt.close(fig)


# ---------------------------------------------------------------------------------------
# Section 2: speed at equal quality

def _warm_up(rnd, renderer, desc, spp, res):
    """One untimed render of the configuration, repeated while Dr.Jit still compiles (peers
    loads a fresh scene per call and the first loads can hash to a different kernel)."""
    warm = []
    for i in range(4):
        _, call = rnd.render(renderer, desc, spp, res, seed=999_000 + i, mitsuba_sampler=SPEED_MITSUBA_SAMPLER)
        warm.append(call)
        if call.compile_s == 0.0:
            break
    return warm


def _rung_stats(spp, calls, warm):
    walls = [c.wall for c in calls]
    return {
        "spp": spp,
        "time": float(np.median(walls)),
        "times": walls,
        "cpu_over_wall": float(np.median([c.cpu / c.wall for c in calls])),
        "first_call_s": warm[0].wall,
        "warmups": len(warm),
        "compile_s": sum(c.compile_s for c in warm),
        "disk_cache_hit": any(c.disk_hit for c in warm),
        "timed_recompiles": sum(1 for c in calls if c.compile_s > 0),
    }


def interleaved_order(renderers, runs):
    """The timed renders of one rung, as (round, renderer): every renderer once per round,
    the order rotated by one each round. A slow spell of a shared machine then falls on
    all renderers alike instead of on whichever ran through it, and no renderer always
    follows the same one (whose cache footprint it would inherit)."""
    n = len(renderers)
    return [(k, renderers[(k + i) % n]) for k in range(runs) for i in range(n)]


def _measure_rung(rnd, renderers, desc, spp, res, runs, seed0):
    """A warm-up per renderer, then `runs` timed renders each with independent seeds, in
    interleaved_order. Returns {renderer: (images, rung stats)} and {renderer: error}."""
    warm, failed = {}, {}
    for r in renderers:
        try:
            warm[r] = _warm_up(rnd, r, desc, spp, res)
        except Exception as e:  # noqa: BLE001 - reported in the tables
            failed[r] = e
    imgs, calls = {r: [] for r in renderers}, {r: [] for r in renderers}
    for k, r in interleaved_order(renderers, runs):
        if r in failed:
            continue
        try:
            img, call = rnd.render(r, desc, spp, res, seed=seed0 + k, mitsuba_sampler=SPEED_MITSUBA_SAMPLER)
        except Exception as e:  # noqa: BLE001
            failed[r] = e
            continue
        imgs[r].append(img)
        calls[r].append(call)
    done = {r: (np.stack(imgs[r]), _rung_stats(spp, calls[r], warm[r])) for r in renderers if r not in failed}
    return done, failed


# Section 2's ratios come with a bootstrap interval: the rounds of each rung are resampled
# with replacement (the same rounds for every renderer: round k of each ran within the same
# seconds of the machine) and the whole fit is redone per resample. It covers the noise of
# the relMSE estimates (K renders each) and of the timings together, which neither the
# ratio nor the per-round time spread shows alone.
BOOTSTRAP_RESAMPLES = 200
BOOTSTRAP_SEED = 20261203
BOOTSTRAP_QUANTILES = (5, 95)  # a 90% interval


def bootstrap_counts(runs, n_boot=BOOTSTRAP_RESAMPLES, seed=BOOTSTRAP_SEED):
    """(n_boot, runs) multiplicities: how often each round appears in each resample."""
    draws = np.random.default_rng(seed).integers(0, runs, size=(n_boot, runs))
    return np.stack([np.bincount(d, minlength=runs) for d in draws]).astype(np.float64)


def resampled_relmse(runs, ref, counts, eps=REL_EPS):
    """relmse_from_runs of every resample at once: counts (B, K) are the multiplicities of
    the K renders `runs` (K, ...) in each resample (all ones: the renders themselves)."""
    runs = np.asarray(runs, np.float64)
    k = runs.shape[0]
    x = runs.reshape(k, -1)
    s1, s2 = counts @ x, counts @ (x * x)
    var = np.maximum(s2 - s1 * s1 / k, 0.0) / (k - 1)
    w = 1.0 / (np.asarray(ref, np.float64).reshape(-1) ** 2 + eps)
    return var @ w / x.shape[1]


def resampled_medians(values, counts):
    """Median of each resample of `values` (K,) with multiplicities counts (B, K)."""
    values = np.asarray(values, np.float64)
    return np.array([np.median(np.repeat(values, c.astype(int))) for c in counts])


def bootstrap_rung(imgs, times, ref, ref_block, counts):
    """One renderer's rung, resampled: relMSE per pixel and over blocks, and the median time."""
    return {"pixel": resampled_relmse(imgs, ref, counts),
            "block": resampled_relmse(to_blocks(imgs), ref_block, counts),
            "time": resampled_medians(times, counts)}


def ratio_interval(peer_boot, kauri_boot, spps, metric, min_spp, marginal=False, q=BOOTSTRAP_QUANTILES):
    """Percentile interval of time_peer / time_kauri at equal error over the resamples.
    `*_boot`: per rung, bootstrap_rung's arrays. The target error cancels in the ratio
    (t = c / target for both), so each resample's ratio is c_peer / c_kauri. Resamples where
    a variance came out 0 (every draw the same render) are left out. None if none is left."""
    def fits(boot):
        err = np.array([b[metric] for b in boot])   # (rungs, B)
        t = np.array([b["time"] for b in boot])
        out = []
        for i in range(err.shape[1]):
            if not np.all(err[:, i] > 0):
                out.append(np.nan)
            elif marginal:
                out.append(marginal_efficiency(spps, err[:, i], t[:, i])[0])
            else:
                out.append(efficiency(spps, err[:, i], t[:, i], min_spp))
        return np.array(out)
    r = fits(peer_boot) / fits(kauri_boot)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return None
    lo, hi = np.percentile(r, q)
    return float(lo), float(hi)


def _interval(data, scene, renderer, metric, key):
    v = data.get(scene, {}).get("renderers", {}).get(renderer, {})
    return v.get("fit", {}).get(metric, {}).get(key) if v.get("status") == "ok" else None


def fmt_ratio(x, interval):
    """A ratio with its bootstrap interval: '1.08 [0.95–1.21]'."""
    if x is None or interval is None:
        return fmt_g(x)
    return f"{fmt_g(x)} [{fmt_g(interval[0])}–{fmt_g(interval[1])}]"


def round_time_ratios(peer_times, kauri_times):
    """Per-round time_peer / time_kauri of one interleaved rung: (min, median, max)."""
    q = np.asarray(peer_times, np.float64) / np.asarray(kauri_times, np.float64)
    return float(q.min()), float(np.median(q)), float(q.max())


# Each renderer converges as fast as it can: kauri with its default (ZSobol) sampler,
# Cycles with its default pattern, Mitsuba with its best sampler. "multijitter" (correlated
# multi-jittered sampling, Kensler 2013) converges fastest of Mitsuba 3's samplers on every
# bench scene: relMSE x time at 256 spp (llvm_ad_rgb) 1.6x better than Mitsuba's default
# "independent" on glossy, 2.5x on cornell, 6.5x on hangar (docs/benchmarks-history.md, cda73de run). It rounds
# some sample counts up (128 -> 132; squares are kept, and peers.render_mitsuba refuses a
# count it would change), so the ladders hold squares. The agreement section keeps "independent": it tests the mean.
SPEED_MITSUBA_SAMPLER = "multijitter"

# The two error scales of section 2: per pixel (the headline metric) and over 4x4-pixel blocks.
# Both renderers splat every sample into all pixels within the filter radius (kauri's default
# reconstruction), so per-pixel noise is correlated between neighbours; the block scale shows
# the error at a coarser grain, where that correlation no longer helps. Both are reported.
METRICS = {"pixel": "per-pixel relMSE", "block": "4×4-block relMSE"}
BLOCK = 4


def to_blocks(runs, size=BLOCK):
    """(..., H, W, C) -> means over size x size pixel blocks."""
    runs = np.asarray(runs, np.float64)
    return block_means(runs, n=runs.shape[-3] // size, border=0)


def fit_renderer(rungs, metric, min_spp):
    """Efficiency c and log-log slope of one renderer's ladder for one metric."""
    spp, err, t = ([g["spp"] for g in rungs], [g["relmse"][metric] for g in rungs], [g["time"] for g in rungs])
    fit = [i for i, x in enumerate(spp) if x >= min_spp]
    c_marginal, overhead = marginal_efficiency(spp, err, t)
    return {"c": efficiency(spp, err, t, min_spp), "slope": loglog_slope([t[i] for i in fit], [err[i] for i in fit]),
            "c_marginal": c_marginal, "overhead_s": overhead}


def section_speed(cfg, names, renderers, skipped, rnd, out_dir, log):
    res, runs = cfg.speed_res, cfg.speed_runs
    data = {}
    for name in names:
        desc = SCENES[name].describe()
        log(f"speed {name}: kauri reference, {cfg.ref_spp} spp at {res}x{res}")
        scene = {"reference": {"renderer": KAURI, "spp": cfg.ref_spp}, "renderers": {}, "target": {}}
        data[name] = scene
        try:
            ref, _ = rnd.render(KAURI, desc, cfg.ref_spp, res, seed=10 ** 6)
        except Exception as e:  # noqa: BLE001
            log(f"speed {name}: reference render failed: {type(e).__name__}: {e}")
            scene["renderers"] = {r: {"status": "failed", "reason": f"reference: {type(e).__name__}: {e}"}
                                  for r in renderers}
            continue
        ref_block = to_blocks(ref)
        rungs = {r: [] for r in renderers}
        boot = {r: [] for r in renderers}  # per rung, bootstrap_rung's arrays (kept out of results.json)
        live = list(renderers)
        for spp in cfg.ladder:
            t = time.perf_counter()
            done, failed = _measure_rung(rnd, live, desc, spp, res, runs, seed0=1000 * spp)
            for r, e in failed.items():
                log(f"speed {name}: {r} failed: {type(e).__name__}: {e}")
                scene["renderers"][r] = {"status": "failed", "reason": f"{type(e).__name__}: {e}", "rungs": rungs[r]}
                live.remove(r)
            for r in live:
                imgs, rung = done[r]
                rung["relmse"] = {"pixel": relmse_from_runs(imgs, ref),
                                  "block": relmse_from_runs(to_blocks(imgs), ref_block)}
                rungs[r].append(rung)
                boot[r].append(bootstrap_rung(imgs, rung["times"], ref, ref_block,
                                              bootstrap_counts(len(rung["times"]), seed=BOOTSTRAP_SEED + spp)))
                log(f"speed {name}: {r:16s} {spp:5d} spp  {rung['time'] * 1e3:8.1f} ms/render  "
                    f"relMSE {rung['relmse']['pixel']:.3e} (4x4 blocks {rung['relmse']['block']:.3e})  "
                    f"cpu/wall {rung['cpu_over_wall']:.2f}  first call {rung['first_call_s']:.2f} s")
            log(f"speed {name}: {spp} spp rung, {len(live)} renderers interleaved, {time.perf_counter() - t:.1f} s")
        for r in live:
            scene["renderers"][r] = {"status": "ok", "rungs": rungs[r],
                                     "fit": {m: fit_renderer(rungs[r], m, cfg.fit_min_spp) for m in METRICS}}
        scene["renderers"] = {r: scene["renderers"][r] for r in renderers if r in scene["renderers"]}
        ok = {r: v for r, v in scene["renderers"].items() if v["status"] == "ok"}
        if KAURI in ok:
            spps = [g["spp"] for g in ok[KAURI]["rungs"]]
            for m in METRICS:
                target = scene["target"][m] = ok[KAURI]["rungs"][-1]["relmse"][m]
                for r, v in ok.items():
                    v["fit"][m]["time_to_target"] = time_to_error(v["fit"][m]["c"], target)
                    v["fit"][m]["time_to_target_marginal"] = time_to_error(v["fit"][m]["c_marginal"], target)
                    if r != KAURI:
                        v["fit"][m]["ratio_interval"] = ratio_interval(boot[r], boot[KAURI], spps, m,
                                                                       cfg.fit_min_spp)
                        v["fit"][m]["ratio_interval_marginal"] = ratio_interval(boot[r], boot[KAURI], spps, m,
                                                                                cfg.fit_min_spp, marginal=True)
        try:
            plot_speed(name, scene, os.path.join(out_dir, f"speed_{name}.png"))
        except Exception as e:  # noqa: BLE001
            log(f"speed {name}: plot failed: {e}")
    try:
        plot_speed_grid(data, os.path.join(out_dir, "speed_all.png"))
    except Exception as e:  # noqa: BLE001
        log(f"speed: grid plot failed: {e}")

    peers_ = [r for r in renderers if r != KAURI]
    summary = {}
    md = [f"Configuration: {res}×{res} px; spp ladder {', '.join(map(str, cfg.ladder))}; per rung one "
          f"warm-up render (repeated while Dr.Jit still compiled), then {runs} timed renders with independent "
          f"seeds, interleaved (every renderer once per round, the order rotated each round); samplers: kauri's "
          f"ZSobol (Owen-scrambled Sobol', neighbouring pixels in one sequence), Mitsuba's `{SPEED_MITSUBA_SAMPLER}` (its fastest-converging here), Cycles' default "
          f"pattern; time = median wall time of the render call; relMSE denominator: kauri at {cfg.ref_spp} spp; "
          f"efficiency c = geometric mean of relMSE × time over rungs ≥ {cfg.fit_min_spp} spp; time to the "
          f"target error t = c / target, target = the relMSE kauri reaches at {cfg.ladder[-1]} spp.",
          "",
          "**The error here is each renderer's noise** (relMSE against its own expected image, estimated "
          "from the independent renders); the bias between renderers is section 1.",
          "",
          "Two scales: **per pixel** (mean over pixels and channels of s² / (ref² + 0.01)) and over "
          "**4×4-pixel blocks** (the same on images averaged over 4×4 blocks). Both renderers splat each "
          "sample into every pixel within the 2-px filter radius (kauri's default `reconstruction='splat'`), "
          "which lowers per-pixel noise about threefold and correlates it between neighbours; over blocks "
          "that correlation no longer helps.", ""]
    for m, title in METRICS.items():
        ttt = {n: {r: v.get("fit", {}).get(m, {}).get("time_to_target") for r, v in d["renderers"].items()}
               for n, d in data.items()}
        ratios = ratio_table(ttt)
        gm = geometric_means(ratios)
        summary[m] = {"time_to_target": ttt, "ratios": ratios, "geometric_mean": gm}
        rows = [[n] + [fmt_ratio(ratios.get(n, {}).get(r), _interval(data, n, r, m, "ratio_interval"))
                       for r in peers_] for n in names]
        rows.append(["geometric mean"] + [fmt_g(gm.get(r)) for r in peers_])
        ratio_md = md_table(["scene"] + [f"{r} / kauri" for r in peers_], rows)
        trows = [[n, fmt_g(data[n]["target"].get(m))] + [fmt_g(ttt[n].get(r)) for r in renderers] for n in names]
        ttt_md = md_table(["scene", "target relMSE"] + [f"{r} (s)" for r in renderers], trows)
        print(f"\n{title}: time to reach kauri's top-rung error (s):\n" + ttt_md, flush=True)
        print(f"\n{title}: ratio time_peer / time_kauri at equal error (> 1: kauri is faster):\n" + ratio_md + "\n",
              flush=True)
        md += [f"### {title}", "",
               "Ratio time_peer / time_kauri to reach the same error (> 1 means kauri is faster), with its "
               f"{BOOTSTRAP_QUANTILES[1] - BOOTSTRAP_QUANTILES[0]}% bootstrap interval in brackets "
               f"({BOOTSTRAP_RESAMPLES} resamples of the interleaved rounds, the fit redone on each):", "",
               ratio_md, "",
               "Time to reach it (s):", "", ttt_md, ""]
    # How far the timing alone moves within this run: the rounds of a rung are interleaved,
    # so round k of every renderer ran within the same few seconds.
    spread = {}
    for n in names:
        ok = {r: v for r, v in data[n]["renderers"].items() if v["status"] == "ok"}
        if KAURI not in ok:
            continue
        kt = ok[KAURI]["rungs"][-1]["times"]
        spread[n] = {r: round_time_ratios(v["rungs"][-1]["times"], kt) for r, v in ok.items()
                     if r != KAURI and len(v["rungs"][-1]["times"]) == len(kt)}
    summary["round_time_ratios"] = spread
    rows = [[n] + [" / ".join(f"{x:.2f}" for x in spread[n][r]) if r in spread.get(n, {}) else "–" for r in peers_]
            for n in names]
    spread_md = md_table(["scene"] + [f"{r} / kauri" for r in peers_], rows)
    print("\nTop rung, time_peer / time_kauri per interleaved round (min / median / max):\n" + spread_md + "\n",
          flush=True)
    md += ["### Timing spread within the run", "",
           f"Top rung ({cfg.ladder[-1]} spp): the render-time ratio time_peer / time_kauri of each interleaved "
           "round (min / median / max over the rounds). The equal-error ratios above are this time ratio "
           "times the renderers' error ratio, so their timing part moves by as much.", "", spread_md, ""]
    # The same without each renderer's fixed per-call cost (scene sync, kernel launch, film
    # set-up): what a long render sees. Cycles re-syncs large meshes on every call.
    for m, title in METRICS.items():
        ttt = {n: {r: v.get("fit", {}).get(m, {}).get("time_to_target_marginal") for r, v in d["renderers"].items()}
               for n, d in data.items() if not n.startswith("_")}
        ratios = ratio_table(ttt)
        gm = geometric_means(ratios)
        summary[m]["marginal"] = {"time_to_target": ttt, "ratios": ratios, "geometric_mean": gm}
        rows = [[n] + [fmt_ratio(ratios.get(n, {}).get(r), _interval(data, n, r, m, "ratio_interval_marginal"))
                       for r in peers_] for n in names]
        rows.append(["geometric mean"] + [fmt_g(gm.get(r)) for r in peers_])
        orows = [[n] + [f"{1e3 * v['fit'][m]['overhead_s']:.0f}" if v.get("status") == "ok" else "–"
                        for v in (data[n]["renderers"].get(r, {}) for r in renderers)] for n in names]
        marg_md = md_table(["scene"] + [f"{r} / kauri" for r in peers_], rows)
        print(f"\n{title}, per-call overhead excluded: ratio time_peer / time_kauri:\n" + marg_md + "\n", flush=True)
        md += [f"### {title}, per-call overhead excluded", "",
               "Each renderer's cost per sample from its top two rungs, times the top rung's spp and relMSE "
               "(`marginal_efficiency`): the ratio a long render sees, where a fixed cost per render call "
               "no longer matters. Ratio time_peer / time_kauri, bootstrap interval in brackets:", "", marg_md, "",
               "Per-call overhead, t_top − spp_top × cost per sample (ms):", "",
               md_table(["scene"] + list(renderers), orows), ""]
    data["_summary"] = summary
    if skipped:
        md += ["Skipped renderers: " + "; ".join(f"`{r}`: {why}" for r, why in skipped.items()), ""]
    md += ["### Per scene", "",
           "Per renderer and rung: median wall time of the render call, CPU time / wall time (threads "
           "actually busy), relMSE per pixel and over 4×4 blocks, relMSE × t (per pixel), the first "
           "(warm-up) call, Dr.Jit compile time in the warm-ups (kernels served from the on-disk cache "
           "~/.drjit compile fast; a first run on a fresh machine compiles them all), renders that still "
           "compiled during the timed runs; per renderer the efficiency c and the log-log slope of relMSE "
           "against time over the fitted rungs (−1 when relMSE ∝ 1/t), per pixel / 4×4 blocks.", ""]
    for n in names:
        d = data[n]
        rows = []
        for r, v in d["renderers"].items():
            if v["status"] != "ok":
                rows.append([r, "failed: " + v["reason"][:80]] + [""] * 10)
                continue
            f = v["fit"]
            for i, g in enumerate(v["rungs"]):
                comp = (f"{g['compile_s']:.2f}" + (" (disk cache)" if g["disk_cache_hit"] else "")
                        if r != KAURI else "–")
                last = i == len(v["rungs"]) - 1
                rows.append([r if i == 0 else "", g["spp"], f"{g['time'] * 1e3:.1f}", f"{g['cpu_over_wall']:.2f}",
                             f"{g['relmse']['pixel']:.3e}", f"{g['relmse']['block']:.3e}",
                             f"{g['relmse']['pixel'] * g['time']:.3e}", f"{g['first_call_s'] * 1e3:.0f}", comp,
                             g["timed_recompiles"],
                             f"{f['pixel']['c']:.3g} / {f['block']['c']:.3g}" if last else "",
                             f"{f['pixel']['slope']:.2f} / {f['block']['slope']:.2f}" if last else ""])
        md += [f"#### {n}", "", md_table(
            ["renderer", "spp", "ms / render", "CPU/wall", "relMSE", "relMSE 4×4", "relMSE·t", "first call (ms)",
             "JIT compile (s)", "recompiles in timed", "c (px / 4×4)", "slope (px / 4×4)"], rows), "",
            f"![speed {n}](speed_{n}.png)", ""]
    md += ["![all scenes](speed_all.png)", ""]
    return data, md


RENDERER_STYLE = {KAURI: ("C3", "o"), "scalar_rgb": ("C0", "s"), "scalar_spectral": ("C1", "D"),
                  "llvm_ad_rgb": ("C2", "^"), "llvm_ad_spectral": ("C4", "v"), CYCLES: ("C5", "P")}


def _speed_axes(ax, name, scene, metric):
    for r, v in scene["renderers"].items():
        if v["status"] != "ok":
            continue
        col, mk = RENDERER_STYLE.get(r, ("k", "x"))
        t = [g["time"] for g in v["rungs"]]
        e = [g["relmse"][metric] for g in v["rungs"]]
        ax.loglog(t, e, marker=mk, color=col, label=r, lw=1.6 if r == KAURI else 1.0, ms=4)
        for g, x, y in zip(v["rungs"], t, e):
            ax.annotate(str(g["spp"]), (x, y), fontsize=6, color=col, xytext=(3, 3), textcoords="offset points")
    if metric in scene.get("target", {}):
        ax.axhline(scene["target"][metric], color="gray", ls=":", lw=0.8)
    ax.set_title(f"{name}: {METRICS[metric]}", fontsize=9)
    ax.set_xlabel("wall time per render (s)", fontsize=8)
    ax.set_ylabel(METRICS[metric] + " (own noise)", fontsize=8)
    ax.tick_params(labelsize=7)
    from matplotlib.ticker import NullFormatter
    ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels overlap on short decades
    ax.grid(True, which="both", alpha=0.25)


def plot_speed(name, scene, path):
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, m in zip(axes, METRICS):
        _speed_axes(ax, name, scene, m)
    axes[0].legend(fontsize=7)
    fig.text(0.01, -0.02, "numbers at the markers: spp; dotted: kauri's top-rung error (the target)", fontsize=7)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


def plot_speed_grid(data, path):
    scenes = {n: d for n, d in data.items() if not n.startswith("_")}
    if not scenes:
        return
    plt = _pyplot()
    n = len(scenes)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.8 * rows), squeeze=False)
    for ax, (name, scene) in zip(axes.flat, scenes.items()):
        _speed_axes(ax, name, scene, "pixel")
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path)
    plt.close(fig)


# ---------------------------------------------------------------------------------------
# Section 3: closeness to the limit (Embree ray replay)


#: Packet widths at which section 3 also replays the rays (kauri.ray_replay(packets=...)).
REPLAY_PACKETS = (8, 16)
# Renders and replays alternate this many times, the best time of each kept: on a shared VM
# a replay of 3 read 25% slow in one run (textured room, 28 against 37-39 M rays/s in the
# runs around it), moving its ratio by 6 points.
REPLAY_REPEATS = 5


def section_ray_replay(cfg, names, threads, log):
    """Closeness to the limit: kauri's ray throughput while rendering against the
    accelerator's alone on the same rays (kauri.ray_replay records a render's ray queries and
    replays them through rtcIntersect1 / rtcOccluded1, with the direct tests of a root
    group's few analytic spheres and disks). Only if the build has kauri._core.ray_replay."""
    import kauri
    if not hasattr(kauri._core, "ray_replay"):
        log("ray replay: not available in this build")
        return {"available": False}, ["Not available in this build (`kauri._core` has no `ray_replay`).", ""]
    import peers
    res, spp = cfg.speed_res, cfg.ladder[-1]
    data, rows = {"available": True, "scenes": {}}, []
    for name in names:
        log(f"ray replay {name}: {spp} spp at {res}x{res}")
        try:
            scene = peers.to_kauri(SCENES[name].describe())
            r = kauri.ray_replay(scene, spp=spp, resolution=(res, res), seed=1, threads=threads, aovs=False,
                                 repeats=REPLAY_REPEATS, packets=REPLAY_PACKETS, **peers.KAURI_PATH_LIMITS)
        except Exception as e:  # noqa: BLE001 - reported in the table
            data["scenes"][name] = {"error": f"{type(e).__name__}: {e}"}
            rows.append([name, f"failed: {type(e).__name__}: {e}"[:80]] + [""] * (5 + len(REPLAY_PACKETS)))
            continue
        packets = r.pop("packet_replay", {})
        data["scenes"][name] = {k: (v if isinstance(v, (int, float, str, bool)) else str(v)) for k, v in r.items()}
        data["scenes"][name]["packet_replay"] = {str(w): p for w, p in packets.items()}
        same = r["hits_match"] and all(p["hits_match"] for p in packets.values())
        rows.append([name, r["render_rays"], f"{r['render_rays_per_second'] / 1e6:.2f}",
                     f"{r['embree_rays_per_second'] / 1e6:.2f}", f"{100 * r['fraction_of_embree']:.1f}%"]
                    + [f"{packets[w]['embree_rays_per_second'] / 1e6:.2f} (×{packets[w]['speedup_over_single']:.2f})"
                       if w in packets else "–" for w in REPLAY_PACKETS]
                    + ["yes" if same else "NO", "yes" if r["complete"] else "no (capped)"])
    table = md_table(["scene", "rays", "render (Mrays/s)", "Embree replay (Mrays/s)", "render / Embree"]
                     + [f"Embree, packets of {w} (Mrays/s)" for w in REPLAY_PACKETS]
                     + ["same hits", "all rays recorded"], rows)
    print("\n" + table + "\n", flush=True)
    return data, [f"Configuration: {res}×{res} px, {spp} spp, {threads} threads, path limits as in "
                  "peers.render_kauri. 'render' is rays traced per second of kauri's whole render (all "
                  "the path-tracing work); 'Embree replay' is rays per second when the same recorded "
                  "ray queries (closest-hit and shadow) are replayed through the accelerator alone (Embree, "
                  "and the direct tests of up to 8 analytic spheres and disks). Renders and replays "
                  f"alternate, best of {REPLAY_REPEATS} each. "
                  "Their ratio is how close the renderer is to pure traversal cost (100% = nothing "
                  "but traversal). 'Embree, packets of N': the same queries in their recorded order, N "
                  "at a time, as Embree packets of incoherent rays (rtcIntersect8/16, rtcOccluded8/16), "
                  "in the same alternation, with the speed-up over single rays in brackets: what "
                  "traversal would cost an integrator that traces N paths at once.", "", table, ""]



# ---------------------------------------------------------------------------------------
# Section 4: memory

def _last_json(text):
    for line in reversed(text.splitlines()):
        try:
            v = json.loads(line)
            if isinstance(v, dict):
                return v
        except ValueError:
            continue
    return {}


def fmt_mem_delta(kib):
    """peak − baseline in MiB; negative (two processes' build peaks differing by more than the
    render added) marked with *."""
    return f"{kib / 1024:.0f}" + ("*" if kib < 0 else "")


def section_memory(cfg, names, renderers, threads, log):
    res, spp = cfg.mem_res, cfg.mem_spp
    data, rows = {}, []
    for name in names:
        data[name] = {}
        for r in renderers:
            log(f"memory {name}: {r} (baseline and render subprocesses, {spp} spp at {res}x{res})")
            rc0, out0, base = run_worker("memory", r, name, res, spp, threads, baseline=True)
            rc1, out1, peak = run_worker("memory", r, name, res, spp, threads, baseline=False)
            if rc0 or rc1:
                why = _failure_reason(rc0, out0) if rc0 else _failure_reason(rc1, out1)
                data[name][r] = {"status": "failed", "reason": why}
                rows.append([name, r, "failed", why[:60], ""])
                continue
            data[name][r] = {"status": "ok", "baseline_kib": base, "peak_kib": peak,
                             "vmhwm_kib": [_last_json(out0).get("vmhwm_kib"), _last_json(out1).get("vmhwm_kib")]}
            rows.append([name, r, f"{base / 1024:.0f}", f"{peak / 1024:.0f}", fmt_mem_delta(peak - base)])
    table = md_table(["scene", "renderer", "baseline (MiB)", "peak (MiB)", "peak − baseline (MiB)"], rows)
    print("\n" + table + "\n", flush=True)
    md = [f"Each figure is the peak resident set (`ru_maxrss` from `os.wait4`) of a fresh Python "
          f"subprocess: 'baseline' imports the renderer and builds the scene (kauri: `peers.to_kauri`; "
          f"Mitsuba: `set_variant` + `load_dict`; Cycles: `import bpy` and the scene built in "
          f"Blender, in the bpy environment's Python), 'peak' does the same and renders once "
          f"({res}×{res} px, {spp} spp, {threads} threads; for LLVM variants including the kernel "
          f"compile or its load from the disk cache). Mitsuba subprocesses do not load kauri. "
          f"Python and NumPy are in both figures; peak − baseline is what rendering adds. The two are "
          f"separate processes, so their building peaks can differ: a difference below zero (marked *) "
          f"means rendering added less than that noise, not that it freed memory.", "", table, ""]
    return data, md


# ---------------------------------------------------------------------------------------
# Report

def path_lanes_scenes(names):
    """The scenes kauri renders with its path lanes (a pixel's paths 8 or 16 at a time in
    vector lanes: every surface of the scene of their kind), from a tiny render of each in a
    process of its own (this one does not load kauri)."""
    code = ("import sys; sys.path.insert(0, %r); import kauri, peers, importlib\n"
            "for n in sys.argv[1:]:\n"
            "    d = importlib.import_module('scenes.' + n).describe()\n"
            "    r = kauri.render(peers.to_kauri(d), spp=1, resolution=(4, 4), aovs=False)\n"
            "    print(n, int(bool(r.stats.get('path_lanes'))))\n") % os.path.dirname(os.path.abspath(__file__))
    try:
        out = subprocess.run([sys.executable, "-c", code, *names], capture_output=True, text=True, timeout=600,
                             check=True).stdout
    except (subprocess.SubprocessError, OSError):
        return []
    return [line.split()[0] for line in out.splitlines() if line.endswith(" 1")]


def machine_info(threads, llvm):
    v = versions()
    return {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "cpu": cpu_model(), "vector_isa": vector_isa(), "cores": os.cpu_count(), "threads": threads,
            "memory_gib": round(mem_total_gib(), 1),
            "os": platform.platform(), "versions": v, "libllvm": llvm, "loadavg_start": loadavg()}


def drjit_lanes_md(target):
    if not target:
        return "– (no LLVM variant ran)"
    cpu, lanes = target
    return (f"target `{cpu}`, {lanes} lanes (Dr.Jit compiles for the widest vectors the CPU has: "
            f"the LLVM variants' ratios are comparable only between runs with the same width)")


def build_report(info, mode, argv, sections_md, thread_check, elapsed, done, load=None):
    v = info["versions"]
    md = [f"# kauri benchmark suite{'' if done else ' (incomplete: still running or interrupted)'}", "",
          f"Generated {info['date']} by `python bench/suite.py {' '.join(argv)}` ({mode} mode), "
          f"{elapsed:.0f} s.", "",
          "## What was measured", "",
          "Every scene of `bench/scenes/` is rendered by kauri and by Mitsuba 3 from the same neutral "
          "description (`bench/peers.py`), all renderers with the same number of threads. Section 1 "
          "checks that kauri and Mitsuba's spectral variant compute the same image (their mean images "
          "and 4×4 block means must differ by no more than noise). Section 2 measures how long each "
          "renderer needs to reach a given noise level: relMSE of a render against the renderer's own "
          "expected image (its variance, from independent renders; bias is not in it), per pixel and on "
          "4×4-pixel block averages, against the wall time of the render call after a warm-up (scene "
          "export and loading are not timed: Mitsuba builds its BVH in `load_dict`, kauri compiles its "
          "scene in the warm-up render and reuses it, as it does for any unchanged scene; JIT compile is "
          "reported separately), summarised as the time "
          "to reach the noise kauri reaches at its highest spp, and as the ratio of each peer's time to "
          "kauri's. kauri uses its default sampler "
          "(ZSobol: Owen-scrambled Sobol', neighbouring pixels in one sequence) and splats samples with the pixel filter; in the speed section Mitsuba "
          f"uses its `{SPEED_MITSUBA_SAMPLER}` sampler (its fastest-converging on these scenes) and in the "
          "agreement section `independent`, and splats samples the same way; "
          "the samplers are part of the comparison. Both render the beauty alone (kauri with "
          "`aovs=False`: no albedo, normal or depth AOVs, which Mitsuba's film does not compute either). "
          "Section 3 compares kauri's ray throughput over a whole "
          "render with Embree's alone on the same recorded rays. Section 4 measures peak resident memory of a "
          "process that renders once, and of one that only loads the renderer and the scene.", "",
          "## Machine", "",
          f"- CPU: {info['cpu']}, {info['cores']} cores, widest vectors {info.get('vector_isa', '–')}; "
          f"memory {info['memory_gib']} GiB; {info['os']}",
          f"- Dr.Jit's LLVM kernels: {drjit_lanes_md(info.get('drjit_llvm'))}; kauri: "
          f"`-march={v.get('kauri_march', '–')}`; path lanes (a pixel's paths "
          f"{v.get('kauri_path_lanes', '–')} at a time in vector lanes) on "
          f"{', '.join(info.get('path_lanes') or []) or 'no scene'}, one path per thread at a time on the others",
          f"- Threads for every renderer: {info['threads']} (kauri: `render(threads=N)`; Mitsuba: "
          f"`drjit.set_thread_count(N)`, after which `drjit.thread_count()` = {info.get('drjit_thread_count', '–')}; "
          f"Cycles: `scene.render.threads = N`)",
          f"- Load average (1/5/15 min) at start: {info['loadavg_start']}; at end: {info.get('loadavg_end', '–')}",
          f"- Versions: kauri {v.get('kauri')} (commit {v.get('commit')}), Mitsuba {v.get('mitsuba')}, Dr.Jit {v.get('drjit', '–')}, "
          f"Blender (Cycles) {v.get('blender', '–')}, Python {v['python']}, NumPy {v['numpy']}",
          f"- Dr.Jit LLVM library (DRJIT_LIBLLVM_PATH): {info['libllvm']}", ""]
    if load:
        md += ["CPU use per section, in cores (this run / other processes on the machine, from "
               "/proc/stat; other load slows the timings down): " + ", ".join(
                   f"{k} {v['own_cores']:.2f} / {v['other_cores']:.2f}" for k, v in load.items()), ""]
    if thread_check:
        md += ["Thread check (median CPU time / wall time of the timed renders at ≥ 16 spp; ≤ threads "
               "means the setting is honoured): " + ", ".join(f"{r} {x:.2f}" for r, x in thread_check.items()), ""]
    titles = {"agreement": "1. Agreement with Mitsuba 3", "speed": "2. Speed at equal quality",
              "replay": "3. Closeness to the limit (Embree ray replay)", "memory": "4. Memory"}
    for key, body in sections_md.items():
        md += [f"## {titles[key]}", ""] + body
    return "\n".join(md) + "\n"


def thread_usage(speed_data, min_spp):
    per = {}
    for name, scene in speed_data.items():
        if name.startswith("_"):
            continue
        for r, v in scene["renderers"].items():
            for g in v.get("rungs", []):
                if g["spp"] >= min_spp:
                    per.setdefault(r, []).append(g["cpu_over_wall"])
    return {r: float(np.median(x)) for r, x in per.items()}


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="bench/suite.py", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Examples:\n  python bench/suite.py --quick\n  python bench/suite.py --scenes cornell,hangar "
               "--threads 1\n  python bench/suite.py --sections speed --out /tmp/bench")
    p.add_argument("--quick", action="store_true",
                   help="low resolution and spp, fewer runs: every section in under 5 minutes on 2 cores")
    p.add_argument("--scenes", default=None,
                   help=f"comma-separated scenes (default: all: {','.join(SCENES)}; --quick leaves out "
                        f"{','.join(sorted(FULL_ONLY))})")
    p.add_argument("--threads", type=int, default=default_threads(),
                   help="threads for every renderer (default: all cores, %(default)s here)")
    p.add_argument("--out", default=os.path.join(BENCH, "results"),
                   help="output directory for report.md, results.json and the PNGs (default: bench/results)")
    p.add_argument("--sections", default=",".join(SECTIONS),
                   help=f"comma-separated sections to run (default: all: {','.join(SECTIONS)})")
    p.add_argument("--cycles-python", default=None,
                   help="a Python with bpy for the Cycles column (default: $KAURI_BPY_PYTHON, else the "
                        "environment scripts/setup_cycles makes, ~/.cache/kauri/bpy-venv)")
    p.add_argument("--no-cycles", action="store_true", help="leave Blender's Cycles out")
    # Internal: subprocess workers for the probe and the memory section.
    p.add_argument("--worker", choices=("probe", "memory"), help=argparse.SUPPRESS)
    p.add_argument("--renderer", help=argparse.SUPPRESS)
    p.add_argument("--scene", help=argparse.SUPPRESS)
    p.add_argument("--res", type=int, help=argparse.SUPPRESS)
    p.add_argument("--spp", type=int, help=argparse.SUPPRESS)
    p.add_argument("--baseline", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.worker:
        return args
    if args.scenes is None:
        args.scenes = ",".join(n for n in SCENES if not (args.quick and n in FULL_ONLY))
    args.scene_list = [s.strip() for s in args.scenes.split(",") if s.strip()]
    bad = [s for s in args.scene_list if s not in SCENES]
    if bad:
        p.error(f"unknown scene(s) {', '.join(bad)}; available: {', '.join(SCENES)}")
    args.section_list = [s.strip() for s in args.sections.split(",") if s.strip()]
    bad = [s for s in args.section_list if s not in SECTIONS]
    if bad:
        p.error(f"unknown section(s) {', '.join(bad)}; available: {', '.join(SECTIONS)}")
    if args.threads < 1:
        p.error("--threads must be >= 1")
    return args


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    args = parse_args(argv)
    if args.worker:
        return _worker_main(args)
    start_launcher()  # before kauri / Mitsuba are loaded here (see run_worker)
    try:
        return _run(args, argv)
    finally:
        stop_launcher()


def _run(args, argv):
    llvm = setup_llvm_env()
    cfg = QUICK if args.quick else FULL
    mode = "quick" if args.quick else "full"
    out_dir = os.path.abspath(args.out)
    os.makedirs(out_dir, exist_ok=True)
    log = Progress()
    info = machine_info(args.threads, llvm)
    names = args.scene_list
    info["path_lanes"] = path_lanes_scenes(names)
    log(f"kauri benchmark suite ({mode}): scenes {', '.join(names)}; {args.threads} threads; "
        f"sections {', '.join(args.section_list)}; output {out_dir}")
    global _cycles_python_arg
    _cycles_python_arg = args.cycles_python
    rnd = Renderers(args.threads, args.cycles_python)
    try:
        return _run_sections(args, argv, cfg, mode, out_dir, log, info, names, rnd)
    finally:
        rnd.close()


def _run_sections(args, argv, cfg, mode, out_dir, log, info, names, rnd):
    results = {"machine": info, "mode": mode, "config": dataclasses.asdict(cfg), "argv": argv}
    sections_md, thread_check = {}, {}

    def write(done=False):
        if done:
            info["loadavg_end"] = loadavg()
        results["elapsed_s"] = log.elapsed()
        write_atomic(os.path.join(out_dir, "results.json"), json.dumps(results, indent=1, default=str))
        write_atomic(os.path.join(out_dir, "report.md"),
                     build_report(info, mode, argv, sections_md, thread_check, log.elapsed(), done,
                                  results.get("cpu_load")))

    have_mitsuba = mitsuba_available()
    variants, skipped = [], {}
    if not have_mitsuba:
        skipped = {v: "mitsuba is not installed" for v in MITSUBA_VARIANTS}
        log("Mitsuba 3 not importable: only kauri is measured")
    elif {"speed", "memory", "agreement"} & set(args.section_list):
        log("probing Mitsuba variants (subprocesses)")
        variants, skipped = probe_variants(MITSUBA_VARIANTS, args.threads, log)
    renderers = [KAURI] + variants
    if args.no_cycles:
        skipped[CYCLES] = "left out (--no-cycles)"
    elif {"speed", "memory", "agreement"} & set(args.section_list):
        log("probing Cycles (bpy subprocess)")
        ok, why = probe_cycles(rnd, log)
        if ok:
            renderers.append(CYCLES)
            info["versions"]["blender"] = rnd.cycles_version()
        else:
            skipped[CYCLES] = why
            log(f"probe: Cycles skipped ({why})")

    load = results["cpu_load"] = {}

    if "agreement" in args.section_list:
        meter = CpuMeter()
        if AGREEMENT_PEER in variants:
            results["agreement"], sections_md["agreement"] = section_agreement(cfg, names, rnd, out_dir, log,
                                                                               cycles=CYCLES in renderers)
        else:
            why = skipped.get(AGREEMENT_PEER, "not available")
            log(f"agreement: skipped, Mitsuba {AGREEMENT_PEER} {why}")
            sections_md["agreement"] = [f"Skipped: Mitsuba `{AGREEMENT_PEER}`: {why}.", ""]
        load["agreement"] = meter.stop()
        write()
    if "speed" in args.section_list:
        meter = CpuMeter()
        results["speed"], sections_md["speed"] = section_speed(cfg, names, renderers, skipped, rnd, out_dir, log)
        load["speed"] = meter.stop()
        thread_check.update(thread_usage(results["speed"], cfg.fit_min_spp))
        info["drjit_thread_count"] = rnd.drjit_threads
        info["drjit_llvm"] = drjit_llvm_target() if any(r.startswith("llvm") for r in renderers) else None
        if info["drjit_llvm"]:
            log(f"Dr.Jit LLVM target {info['drjit_llvm'][0]}, {info['drjit_llvm'][1]} lanes")
        over = {r: x for r, x in thread_check.items() if x > 1.15 * args.threads}
        log(f"speed section: other processes used {load['speed']['other_cores']:.2f} cores on average")
        log("CPU/wall per renderer: " + ", ".join(f"{r} {x:.2f}" for r, x in thread_check.items())
            + (f"  WARNING: more than {args.threads} threads busy: {over}" if over else ""))
        write()
    if "replay" in args.section_list:
        meter = CpuMeter()
        results["replay"], sections_md["replay"] = section_ray_replay(cfg, names, args.threads, log)
        load["replay"] = meter.stop()
        write()
    if "memory" in args.section_list:
        meter = CpuMeter()
        results["memory"], sections_md["memory"] = section_memory(cfg, names, renderers, args.threads, log)
        load["memory"] = meter.stop()
        write()
    write(done=True)
    log(f"done in {log.elapsed():.0f} s: {os.path.join(out_dir, 'report.md')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
