"""The tree shows the layers: engine/ holds one package per layer, and a module imports only its
own layer and those below it, so the scene model, the file formats and the GPU plumbing can be
read, tested and reused without what is built on them."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENGINE = ROOT / "engine"
# Bottom to top: each layer may import those before it.
LAYERS = ("core", "scene", "formats", "gpu", "voxels", "passes", "frame", "app")
# Layers whose modules import without a GL library, a window or a display.
GL_FREE = ("core", "scene", "formats")
GL_MODULES = ("moderngl", "glfw", "imgui_bundle", "OpenGL")


def module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path):
    """Every module a file imports, at its top or inside a function, as absolute dotted names."""
    package = module_name(path).split(".")
    if path.name != "__init__.py":
        package = package[:-1]
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            yield module
            yield from (f"{module}.{alias.name}" for alias in node.names)


def layer_of(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "engine" and parts[1] in LAYERS else None


def engine_files():
    return sorted(path for path in ENGINE.rglob("*.py") if "__pycache__" not in path.parts)


def test_every_module_of_engine_lies_in_a_layer_package():
    loose = [path.name for path in ENGINE.glob("*.py") if path.name != "__init__.py"]
    packages = {path.name for path in ENGINE.iterdir() if (path / "__init__.py").is_file()}
    assert loose == [], "modules outside every layer package"
    assert packages == set(LAYERS), "a package of engine/ that is not a layer, or a layer without its package"


def test_no_module_imports_a_layer_above_its_own():
    upward = []
    for path in engine_files():
        own = layer_of(module_name(path))
        if own is None:  # engine/__init__.py: the Python API, above every layer
            continue
        for module in imported_modules(path):
            used = layer_of(module)
            if used is not None and LAYERS.index(used) > LAYERS.index(own):
                upward.append(f"{path.relative_to(ROOT)} imports {module}")
    assert upward == []


def test_the_scene_model_and_the_file_formats_import_no_gl():
    with_gl = [f"{path.relative_to(ROOT)} imports {module}"
               for path in engine_files() if layer_of(module_name(path)) in GL_FREE
               for module in imported_modules(path) if module.split(".")[0] in GL_MODULES]
    assert with_gl == []
