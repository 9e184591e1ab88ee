"""Prints the CMake build folder scikit-build-core uses for this Python (pyproject.toml:
build-dir = "build/{wheel_tag}"), for the Makefile and scripts/pgo_build."""
import sys
import sysconfig

tag = f"cp{sys.version_info[0]}{sys.version_info[1]}"
print(f"build/{tag}-{tag}-{sysconfig.get_platform().replace('-', '_').replace('.', '_')}")
