"""The instruction-set dispatch (python/kauri/_isa.py): which compiled core `import kauri`
loads, and that the x86-64-v4 core renders the image the base core renders."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import kauri
from kauri import _isa

V4 = set(_isa.X86_64_V4_FLAGS)
AVX2_ONLY = {"sse4_2", "avx", "avx2", "fma", "bmi2"}
BOTH = {"base", "x86-64-v4"}


def test_auto_takes_the_widest_core_the_cpu_runs():
    assert _isa.choose(None, AVX2_ONLY | V4, BOTH) == "x86-64-v4"
    assert _isa.choose("auto", AVX2_ONLY | V4, BOTH) == "x86-64-v4"
    assert _isa.choose("", AVX2_ONLY, BOTH) == "base"
    # One AVX-512 subset missing (a CPU with avx512f but not avx512bw, such as Knights
    # Landing) is not x86-64-v4.
    assert _isa.choose(None, AVX2_ONLY | (V4 - {"avx512bw"}), BOTH) == "base"
    assert _isa.choose(None, None, BOTH) == "base"  # flags unknown: the safe core
    assert _isa.choose(None, AVX2_ONLY | V4, {"base"}) == "base"  # a build without the v4 core


def test_forced_choices_and_their_errors():
    assert _isa.choose("base", AVX2_ONLY | V4, BOTH) == "base"
    assert _isa.choose(" x86-64-v4 ", AVX2_ONLY | V4, BOTH) == "x86-64-v4"
    with pytest.raises(ImportError, match=r"KAURI_ISA='avx512': expected one of auto, base, x86-64-v4"):
        _isa.choose("avx512", AVX2_ONLY | V4, BOTH)
    with pytest.raises(ImportError, match=r"this CPU lacks avx512cd, avx512vl"):
        _isa.choose("x86-64-v4", AVX2_ONLY | (V4 - {"avx512cd", "avx512vl"}), BOTH)
    with pytest.raises(ImportError, match=r"has no x86-64-v4 core \(it has: base\)"):
        _isa.choose("x86-64-v4", AVX2_ONLY | V4, {"base"})


def test_cpu_flags_reads_the_first_flags_line(tmp_path):
    f = tmp_path / "cpuinfo"
    f.write_text("processor\t: 0\nvendor_id\t: AuthenticAMD\nflags\t\t: fpu sse2 avx2 avx512f\n\n"
                 "processor\t: 1\nflags\t\t: fpu\n")
    assert _isa.cpu_flags(str(f)) == {"fpu", "sse2", "avx2", "avx512f"}
    f.write_text("processor\t: 0\nFeatures\t: fp asimd\n")  # an arm64 kernel's wording
    assert _isa.cpu_flags(str(f)) is None
    assert _isa.cpu_flags(str(tmp_path / "missing")) is None


def test_loaded_core_matches_the_choice():
    want = _isa.choose(os.environ.get("KAURI_ISA"), _isa.cpu_flags(), set(kauri.build_info["cores"]))
    assert kauri._core is sys.modules["kauri._core"]
    assert (kauri.build_info["march"] == "x86-64-v4") == (want == "x86-64-v4")


_RENDER = textwrap.dedent("""
    import sys, numpy as np, kauri
    from kauri import demo
    out = kauri.render(demo.build(), spp=32, resolution=(32, 32), seed=5, threads=2, aovs=False)
    np.save(sys.argv[1], out.rgba[:, :, :3])
    print(kauri.build_info["march"])
""")


def _render_with(isa, path):
    env = dict(os.environ, KAURI_ISA=isa)
    r = subprocess.run([sys.executable, "-c", _RENDER, str(path)], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip(), np.load(path)


@pytest.mark.skipif("x86-64-v4" not in kauri.build_info["cores"] or _isa.missing_v4_flags(_isa.cpu_flags()) != [],
                    reason="needs the x86-64-v4 core and a CPU with AVX-512")
def test_v4_core_renders_the_base_core_image(tmp_path):
    march_base, base = _render_with("base", tmp_path / "base.npy")
    march_v4, v4 = _render_with("x86-64-v4", tmp_path / "v4.npy")
    assert march_base != "x86-64-v4" and march_v4 == "x86-64-v4"
    # The same paths and samples; only the compiler's instruction choices differ (FMA
    # contraction, vector widths), so most pixels agree to float rounding and a path that
    # a last-bit difference sends elsewhere changes a pixel by one sample's worth.
    assert np.all(np.isfinite(v4))
    close = np.isclose(v4, base, rtol=1e-4, atol=1e-5).all(axis=2)
    assert close.mean() > 0.9, close.mean()
    assert abs(v4.mean() / base.mean() - 1) < 0.01
