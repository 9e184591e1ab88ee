"""bench/ab_builds.py without rendering: the paired ratios, their summary, the folders it
accepts and its argument checks."""
import importlib.util
import os

import pytest

_PATH = os.path.join(os.path.dirname(__file__), "..", "..", "bench", "ab_builds.py")
_spec = importlib.util.spec_from_file_location("bench_ab_builds", _PATH)
ab = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ab)


def test_ratios_pair_renders_by_index():
    assert ab.paired_ratios([1.0, 2.0, 4.0], [1.5, 2.0, 2.0]) == [1.5, 1.0, 0.5]
    with pytest.raises(ValueError):
        ab.paired_ratios([1.0], [1.0, 2.0])


def test_summary_gives_median_and_quartiles():
    s = ab.summary([0.9, 1.0, 1.1, 1.2, 1.3])
    assert s.startswith("median 1.100, quartiles ") and s.endswith("n=5")
    assert ab.summary([1.0, 3.0]) == "median 2.000 (n=2)"


def test_package_dir_accepts_a_package_folder_and_names_a_bad_one(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "kauri").mkdir(parents=True)
    assert ab.package_dir(str(pkg), str(tmp_path), "a") == str(pkg)
    with pytest.raises(SystemExit, match="neither a package folder"):
        ab.package_dir(str(tmp_path / "empty"), str(tmp_path), "b")


def test_package_dir_builds_one_from_a_build_folder(tmp_path):
    build = tmp_path / "build"
    build.mkdir()
    (build / "_core.cpython-311-x86_64-linux-gnu.so").write_bytes(b"\x7fELF")
    out = ab.package_dir(str(build), str(tmp_path), "b")
    assert os.path.isfile(os.path.join(out, "kauri", "__init__.py"))
    assert os.path.isfile(os.path.join(out, "kauri", "_core.cpython-311-x86_64-linux-gnu.so"))


def test_arguments_are_checked():
    with pytest.raises(SystemExit):
        ab.main(["--a", "x", "--b", "y", "--rounds", "0"])
    with pytest.raises(SystemExit):
        ab.main(["--a", "x", "--b", "y", "--scene", "nope"])
