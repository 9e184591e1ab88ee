"""Which compiled core this process loads: the instruction-set dispatch.

A build on an x86-64-v3 (AVX2) machine whose compiler knows x86-64-v4 (AVX-512) compiles
the renderer twice: ``kauri._core`` for the build's target (the "base" core: x86-64-v3, or
whatever KAURI_ARCH chose) and ``kauri._core_v4`` for x86-64-v4.
Importing kauri picks the widest one the CPU runs, as Cycles and Embree choose their
kernels at run time: a farm's AVX-512 nodes get the AVX-512 code (3-4% less render time
on the Zen 4 of docs/benchmarks.md), its AVX2 nodes the same package without an illegal
instruction. ``KAURI_ISA`` overrides the choice (for A/B timings and for pinning a farm
to one code path): ``auto`` (default), ``base`` or ``x86-64-v4``.

The module is plain Python on purpose: the check must run before any code compiled for
AVX-512 is loaded.
"""
from __future__ import annotations

import importlib
import importlib.util
import os
import sys

#: The CPU features x86-64-v4 adds to x86-64-v3 (the psABI's level 4), as Linux names them
#: in /proc/cpuinfo. The kernel lists avx512* only where it also saves the AVX-512 state on
#: context switches, so the flags answer "may this process run AVX-512 code".
X86_64_V4_FLAGS = ("avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl")

#: KAURI_ISA value -> the core module built for it ("base": the build's own target).
MODULES = {"base": "_core", "x86-64-v4": "_core_v4"}


def cpu_flags(cpuinfo: str = "/proc/cpuinfo") -> set[str] | None:
    """The CPU's feature flags (the first processor's ``flags`` line), or None where the
    file is missing or has none (not Linux): then only the baseline core is chosen."""
    try:
        with open(cpuinfo, encoding="ascii", errors="replace") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "flags":
                    return set(value.split())
    except OSError:
        return None
    return None


def missing_v4_flags(flags: set[str] | None) -> list[str]:
    """The x86-64-v4 features `flags` lacks (all of them when the flags are unknown)."""
    if flags is None:
        return list(X86_64_V4_FLAGS)
    return [f for f in X86_64_V4_FLAGS if f not in flags]


def choose(requested: str | None, flags: set[str] | None, available: set[str]) -> str:
    """The ISA to load: `requested` is KAURI_ISA (None or "" or "auto": the widest that
    `flags` allow among `available`, the ISAs this build has modules for). Raises
    ImportError, naming what was expected, for an unknown value, an ISA this build lacks
    or one the CPU cannot run."""
    req = (requested or "auto").strip()
    if req == "auto":
        if "x86-64-v4" in available and not missing_v4_flags(flags):
            return "x86-64-v4"
        return "base"
    if req not in MODULES:
        raise ImportError(f"KAURI_ISA={req!r}: expected one of auto, {', '.join(MODULES)}")
    if req not in available:
        raise ImportError(f"KAURI_ISA={req}: this kauri build has no {req} core (it has: {', '.join(sorted(available))}); "
                          "build on a machine whose compiler supports it, or unset KAURI_ISA")
    if req == "x86-64-v4":
        missing = missing_v4_flags(flags)
        if missing:
            raise ImportError(f"KAURI_ISA=x86-64-v4: this CPU lacks {', '.join(missing)} (/proc/cpuinfo); "
                              "use KAURI_ISA=base or auto")
    return req


def load_core(package: str):
    """Imports the core `choose` picks and registers it as ``<package>._core``, so that
    ``from . import _core`` anywhere in the package gets it. Returns (module, its ISA, the
    ISAs this build has cores for, as a sorted list)."""
    available = {isa for isa, name in MODULES.items()
                 if name == "_core" or importlib.util.find_spec(f"{package}.{name}") is not None}
    isa = choose(os.environ.get("KAURI_ISA"), cpu_flags(), available)
    module = importlib.import_module(f"{package}.{MODULES[isa]}")
    sys.modules[f"{package}._core"] = module
    return module, isa, sorted(available)
