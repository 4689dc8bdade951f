"""The package stands on its own: the built wheel and sdist carry what qzs needs away from here.

The wheel is built the way a user's ``pip install .`` builds it (``pip wheel``; without build
isolation, so no network: the ``test`` extra pins ``setuptools>=77``, which writes PEP 639
license files), from a copy of the tree in a temporary folder, so no ``build/`` or
``*.egg-info`` is left in the working tree. Then its contents are checked against the
project's own declarations: the LICENSE in ``.dist-info/licenses/``, ``py.typed``, every file
that pyproject.toml's ``[tool.setuptools.package-data]`` patterns match in ``src/qzs`` (the
shipped TOML studies, sweeps and hexapod setups; documentation pages if the package ships
them), every module, and the ``qzs`` console script. The sdist must carry the LICENSE too.
"""
import configparser
import shutil
import subprocess
import sys
import tarfile
import tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "src" / "qzs"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
#: What a build reads: the rest of the repository (tests, docs site, results) is not shipped.
BUILD_INPUTS = ("pyproject.toml", "README.md", "LICENSE", "src")


def package_data_files():
    """Every file under src/qzs that a ``[tool.setuptools.package-data]`` pattern matches,
    as a path inside the wheel (``qzs/workflows/paper/study_files/01_spring.toml``)."""
    patterns = PYPROJECT["tool"]["setuptools"]["package-data"]["qzs"]
    return sorted({f"qzs/{path.relative_to(SOURCE).as_posix()}"
                   for pattern in patterns for path in SOURCE.glob(pattern) if path.is_file()})


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """``(wheel member names, wheel, sdist member names)`` of a fresh build of this tree."""
    import setuptools
    major = int(setuptools.__version__.split(".")[0])
    assert major >= 77, (f"setuptools {setuptools.__version__} cannot write PEP 639 license "
                         f"files: install the test extra (pip install -e '.[test]')")
    tree = tmp_path_factory.mktemp("tree")
    for name in BUILD_INPUTS:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, tree / name,
                            ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
        else:
            shutil.copy2(source, tree / name)
    out = tmp_path_factory.mktemp("dist")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "--no-index", "--quiet", "-w", str(out), str(tree)],
                   check=True, capture_output=True, text=True)
    subprocess.run([sys.executable, "-c",
                    f"import setuptools.build_meta as b; b.build_sdist({str(out)!r})"],
                   cwd=tree, check=True, capture_output=True, text=True)
    (wheel,) = out.glob("qzs-*.whl")
    (sdist,) = out.glob("qzs-*.tar.gz")
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    with tarfile.open(sdist) as archive:
        sdist_names = {name.split("/", 1)[1] for name in archive.getnames() if "/" in name}
    return names, wheel, sdist_names


def dist_info(names):
    (folder,) = {name.split("/")[0] for name in names if name.split("/")[0].endswith(".dist-info")}
    return folder


def test_the_wheel_carries_the_license_text(built):
    names, wheel, _ = built
    member = f"{dist_info(names)}/licenses/LICENSE"
    assert member in names, f"no {member} in {wheel.name}"
    with zipfile.ZipFile(wheel) as archive:
        shipped = archive.read(member).decode()
        metadata = archive.read(f"{dist_info(names)}/METADATA").decode()
    assert shipped == (ROOT / "LICENSE").read_text()
    assert "BSD 3-Clause" in shipped and "The qzs developers" in shipped
    assert "License-Expression: BSD-3-Clause" in metadata
    assert "License-File: LICENSE" in metadata


def test_the_sdist_carries_the_license_and_the_marker(built):
    _, _, sdist_names = built
    assert "LICENSE" in sdist_names
    assert "src/qzs/py.typed" in sdist_names


def test_the_wheel_ships_py_typed(built):
    """PEP 561: without the marker, mypy ignores the package's hints in a user's code."""
    names, _, _ = built
    assert "qzs/py.typed" in names
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"]["qzs"]


def test_every_package_data_file_is_in_the_wheel(built):
    """The shipped TOML files, any docs pages the package ships: whatever the patterns match."""
    names, wheel, _ = built
    expected = package_data_files()
    assert any(name.startswith("qzs/workflows/paper/study_files/") for name in expected)
    assert any(name.startswith("qzs/workflows/sweeps/sweep_files/") for name in expected)
    assert any(name.startswith("qzs/workflows/hexapod/hexapod_files/") for name in expected)
    assert any(name.startswith("qzs/workflows/design_space/problem_files/") for name in expected)
    missing = [name for name in expected if name not in names]
    assert not missing, f"{wheel.name} lacks {missing}"


def test_every_data_file_of_the_package_is_declared():
    """A TOML or Markdown file put under src/qzs but matched by no package-data pattern would be
    missing from every installed copy: each one must be declared."""
    declared = set(package_data_files())
    found = {f"qzs/{path.relative_to(SOURCE).as_posix()}"
             for suffix in ("*.toml", "*.md", "*.json", "*.csv")
             for path in SOURCE.rglob(suffix)}
    assert not found - declared, (f"not declared in [tool.setuptools.package-data]: "
                                  f"{sorted(found - declared)}")


def test_every_module_and_the_console_script_are_in_the_wheel(built):
    names, wheel, _ = built
    modules = {f"qzs/{path.relative_to(SOURCE).as_posix()}" for path in SOURCE.rglob("*.py")}
    missing = sorted(modules - names)
    assert not missing, f"{wheel.name} lacks {missing}"
    with zipfile.ZipFile(wheel) as archive:
        text = archive.read(f"{dist_info(names)}/entry_points.txt").decode()
    entry_points = configparser.ConfigParser()
    entry_points.read_string(text)
    assert entry_points["console_scripts"]["qzs"] == PYPROJECT["project"]["scripts"]["qzs"]


def test_nothing_but_the_package_is_in_the_wheel(built):
    """No tests, benchmarks, results or caches travel with the package."""
    names, wheel, _ = built
    top = {name.split("/")[0] for name in names}
    assert top == {"qzs", dist_info(names)}, f"{wheel.name}: {sorted(top)}"
    assert not [name for name in names if "__pycache__" in name or name.endswith(".pyc")]
