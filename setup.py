"""The packages: every one found under engine/, and the top-level glsl/ as engine.glsl
(pyproject.toml holds everything else)."""
from setuptools import find_packages, setup

setup(packages=[*find_packages(include=["engine", "engine.*"]), "engine.glsl"])
