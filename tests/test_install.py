"""Installed like any Python package: a wheel built from the repository holds the engine and its
shaders, and renders from any directory.

The wheel is built from a copy of the files it is made from (so the build leaves nothing in the
checkout) with this environment's setuptools, without build isolation (no network), and goes
into a fresh virtual environment without its dependencies. That environment imports them from
this one's site-packages through a .pth line: .pth files in a directory added that way are not
read, so this environment's editable install of the checkout stays out of it.
"""
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
CORNELL = ROOT / "scenes" / "cornell_box.json"
WHEEL_SOURCES = ["pyproject.toml", "setup.py", "README.md", "engine", "glsl"]
SHADER_SUFFIXES = {".vert", ".frag", ".geom", ".comp", ".glsl"}
PIP = [sys.executable, "-m", "pip", "--disable-pip-version-check"]


def run(*args, cwd=None):
    result = subprocess.run(list(map(str, args)), cwd=cwd, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    source = tmp_path_factory.mktemp("source")
    for name in WHEEL_SOURCES:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, source / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy(ROOT / name, source / name)
    dist = tmp_path_factory.mktemp("dist")
    run(*PIP, "wheel", "--no-deps", "--no-build-isolation", "--no-index", "-w", dist, source)
    (built,) = dist.glob("vct-*.whl")
    return built


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory):
    """A fresh virtual environment with the wheel installed, its dependencies read from here."""
    venv = tmp_path_factory.mktemp("venv").resolve()
    run(sys.executable, "-m", "venv", "--without-pip", venv)
    python = venv / "bin" / "python"
    run(*PIP, "--python", python, "install", "--no-deps", "--no-index", wheel)
    site_packages = Path(run(python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))").strip())
    dependencies = dict.fromkeys([sysconfig.get_path("purelib"), sysconfig.get_path("platlib")])
    (site_packages / "dependencies.pth").write_text("".join(f"{path}\n" for path in dependencies))
    return venv


def test_the_wheel_holds_every_engine_module_and_shader(wheel):
    modules = {path.relative_to(ROOT).as_posix() for path in (ROOT / "engine").rglob("*.py")}
    shaders = {f"engine/{path.relative_to(ROOT).as_posix()}" for path in (ROOT / "glsl").rglob("*")
               if path.suffix in SHADER_SUFFIXES}
    with zipfile.ZipFile(wheel) as archive:
        missing = (modules | shaders) - set(archive.namelist())
    assert shaders and not missing, sorted(missing)


def test_a_wheel_built_from_the_repository_renders_from_any_directory(venv, tmp_path):
    """`vct render` of the installed wheel, run outside the checkout, uses the engine and the
    shaders of the wheel and writes a lit image."""
    where = run(venv / "bin" / "python", "-c", "import engine.gpu.shaders; print(engine.__file__); print(engine.gpu.shaders.GLSL_ROOT)",
                cwd=tmp_path).splitlines()
    assert all(Path(path).is_relative_to(venv) for path in where), where
    png = tmp_path / "cornell.png"
    run(venv / "bin" / "vct", "render", CORNELL, "--grid", "16", "--width", "64", "--height", "64", "--out", png,
        cwd=tmp_path)
    with Image.open(png) as image:
        pixels = np.asarray(image.convert("RGB"), dtype=np.float64)
    assert pixels.shape == (64, 64, 3) and pixels.mean() > 10, pixels.mean()
