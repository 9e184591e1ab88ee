"""The kauri command line: help, rendering a Python scene file, and its errors."""
import subprocess
import sys
import textwrap

import numpy as np
import pytest


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "kauri", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=300)


def test_help_lists_commands_and_options():
    r = run("--help")
    assert r.returncode == 0 and "render" in r.stdout
    r = run("render", "--help")
    assert r.returncode == 0
    for opt in ("--spp", "--res", "--threads", "--seed", "--time-limit", "--no-aovs", "--light-sampler", "-o",
                "SCENE"):
        assert opt in r.stdout


def test_version():
    r = run("--version")
    assert r.returncode == 0 and r.stdout.startswith("kauri ")
    assert "path lanes: " in r.stdout


SCENE = textwrap.dedent("""
    import kauri

    def build():
        s = kauri.Scene()
        s.add_sphere(center=(0, 0, 0), radius=1, material=kauri.Lambert(albedo=(0.5, 0.5, 0.5)))
        s.add_environment(color=(1, 1, 1))
        s.set_camera(eye=(0, 0, 4), target=(0, 0, 0), fov=40)
        return s
""")


def test_render_scene_file_writes_exr_and_png(tmp_path):
    scene = tmp_path / "ball.py"
    scene.write_text(SCENE)
    out = tmp_path / "ball.exr"
    r = run("render", str(scene), "-o", str(out), "--spp", "4", "--res", "32x24", "--seed", "3", "-q")
    assert r.returncode == 0, r.stderr
    assert out.exists() and (tmp_path / "ball.png").exists()
    assert "rays/s" in r.stderr
    OpenEXR = pytest.importorskip("OpenEXR")
    with OpenEXR.File(str(out), separate_channels=True) as f:
        assert f.channels()["R"].pixels.shape == (24, 32)
        assert np.all(np.isfinite(f.channels()["R"].pixels))
        assert "albedo.R" in f.channels() and "Z" in f.channels()
    beauty = tmp_path / "beauty.exr"
    r = run("render", str(scene), "-o", str(beauty), "--spp", "4", "--res", "32x24", "--seed", "3", "-q", "--no-aovs")
    assert r.returncode == 0, r.stderr
    with OpenEXR.File(str(beauty), separate_channels=True) as f, OpenEXR.File(str(out), separate_channels=True) as g:
        assert set(f.channels()) == {"R", "G", "B", "A"}
        np.testing.assert_array_equal(f.channels()["R"].pixels, g.channels()["R"].pixels)
    # An environment alone: no finite lights, so both light samplers give the same image.
    power = tmp_path / "power.exr"
    r = run("render", str(scene), "-o", str(power), "--spp", "4", "--res", "32x24", "--seed", "3", "-q",
            "--light-sampler", "power")
    assert r.returncode == 0, r.stderr
    with OpenEXR.File(str(power), separate_channels=True) as f, OpenEXR.File(str(out), separate_channels=True) as g:
        np.testing.assert_array_equal(f.channels()["R"].pixels, g.channels()["R"].pixels)
    r = run("render", str(scene), "-o", str(power), "--light-sampler", "bvh", "-q")
    assert r.returncode != 0 and "--light-sampler" in r.stderr


def test_demo_render_shows_progress(tmp_path):
    r = run("render", "-o", str(tmp_path / "demo.exr"), "--spp", "2", "--res", "32x32")
    assert r.returncode == 0, r.stderr
    assert "samples/s" in r.stderr and "ETA" in r.stderr


def test_errors_are_reported_not_raised(tmp_path):
    r = run("render", str(tmp_path / "missing.py"))
    assert r.returncode != 0 and "no such file" in r.stderr
    bad = tmp_path / "bad.py"
    bad.write_text("def build():\n    return 42\n")
    r = run("render", str(bad), "-o", str(tmp_path / "x.exr"))
    assert r.returncode != 0 and "expected kauri.Scene" in r.stderr
    r = run("render", "--res", "abc")
    assert r.returncode != 0 and "WIDTHxHEIGHT" in r.stderr
    broken = tmp_path / "broken.py"
    broken.write_text(SCENE.replace("radius=1,", "radius=-1,"))
    r = run("render", str(broken), "-o", str(tmp_path / "x.exr"))
    assert r.returncode != 0 and "sphere 'sphere'" in r.stderr and "radius" in r.stderr
    assert "Traceback" not in r.stderr
