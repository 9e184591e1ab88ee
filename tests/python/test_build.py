"""The build the tests run against is the one users get: `make build` compiles kauri with a
profile of scripts/pgo_train.py's renders (scripts/pgo_build) unless KAURI_PGO=0."""
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import kauri

ROOT = Path(__file__).resolve().parents[2]


def test_build_info_names_compiler_target_and_profile():
    b = kauri.build_info
    assert set(b) == {"compiler", "march", "pgo", "cores", "path_lanes"}
    assert "base" in b["cores"] and set(b["cores"]) <= {"base", "x86-64-v4"}
    assert b["pgo"] in ("off", "generate", "use")
    assert b["compiler"].split()[0] in ("GNU", "Clang", "AppleClang") and b["march"]


def test_path_lanes_follow_the_loaded_core():
    # 16 lanes in the AVX-512 core, 8 in the AVX2 one (0: a build without the vector types).
    b = kauri.build_info
    assert b["path_lanes"] in ((16,) if b["march"] == "x86-64-v4" else (8, 0))


def test_default_build_is_profile_guided():
    # An instrumented build ("generate") must never be what is installed, and `make build`
    # (scripts/pgo_build) installs the profile-guided one unless told KAURI_PGO=0.
    want = "off" if os.environ.get("KAURI_PGO") == "0" else "use"
    if kauri.build_info["compiler"].split()[0] != "GNU":
        want = "off"
    assert kauri.build_info["pgo"] == want


def test_training_scenes_render_finite_and_lit():
    # The training workload is a real render of every scene it builds: a scene that fails
    # to build or renders black would leave its code paths out of the profile.
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import pgo_train
    finally:
        sys.path.pop(0)
    for build in (pgo_train.loft, pgo_train.studio, pgo_train.lamps):
        out = kauri.render(build(), spp=2, resolution=(24, 18), seed=3, threads=2, aovs=False)
        rgb = out.rgba[:, :, :3]
        assert np.all(np.isfinite(rgb)), build.__name__
        assert rgb.mean() > 0.05, build.__name__


def test_version_reports_the_build():
    r = subprocess.run([sys.executable, "-m", "kauri", "--version"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0
    assert f"profile-guided: {kauri.build_info['pgo']}" in r.stdout and kauri.build_info["march"] in r.stdout
