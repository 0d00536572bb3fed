# SPDX-License-Identifier: MIT
# Paths the tests need: ctest sets them (python/CMakeLists.txt); by hand, they default to the
# source tree and build/ next to it.
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("SDFCCD_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BUILD_DIR = SOURCE_DIR / "build"


def _program(env, default):
    p = pathlib.Path(os.environ.get(env, BUILD_DIR / default))
    if not p.exists():
        pytest.skip(f"{p} is not built (set {env})")
    return p


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def cases_exe():
    return _program("SDFCCD_CASES_EXE", "samples/sdfccd_cases")


@pytest.fixture(scope="session")
def layout_probe():
    return _program("SDFCCD_LAYOUT_PROBE", "python/sdfccd_layout_probe")


@pytest.fixture(scope="session")
def readme_example():
    return _program("SDFCCD_README_EXAMPLE", "tests/readme_example")
