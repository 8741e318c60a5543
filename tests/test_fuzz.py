"""Fuzzing (hypothesis): mutated scene files, mesh files and command lines never end in a
traceback, a hang, a non-finite image or a lost file.

Each case starts from a valid input and mutates it: scene files and glTF documents get values
replaced (numbers at the edges of the float ranges, wrong types, hostile file names), keys
and list items deleted or duplicated, and scene nodes nested into groups; GLB files get bytes
of their headers, JSON and binary chunks overwritten, or are cut short; MTL and OBJ files get
statements' arguments replaced, lines deleted, duplicated or added; command lines get their
options replaced by edge values. The property, for every case: exit 0 with finite output, or
exit 2 with one stderr line "vct: error: ..." naming the file and the field (or the option),
and no file created or changed (lines "vct: warning: ..." may come before either).

Reproducible and bounded: derandomize=True draws the same examples on every run (the seed is
derived from the test itself; no example database), so a failure reports the same falsifying
example each time; each test has a fixed number of examples and a deadline per example, with
16x16 images at grid 16. Renders run in-process through engine.app.cli.run (main without its
filter of library warnings, so that a warning on the way fails the test); the last test runs
a few cases as real processes to check exit codes and stderr end to end.
"""
import contextlib
import copy
import io
import json
import shutil
import struct
import subprocess
import sys
import tempfile
import warnings
from datetime import timedelta
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine import SceneError, VctWarning, load_scene
from engine.app.cli import run
from engine.core.transforms import gl_bytes
from test_mesh_files import MTL, OBJ, two_material_gltf, write_model_scene, write_obj  # tests/ is on sys.path
from test_scene_file import DATA, write_scene

ROOT = Path(__file__).resolve().parent.parent
SMALL = ["--width", "16", "--height", "16", "--grid", "16"]


def fuzz_settings(examples, deadline_seconds):
    return settings(max_examples=examples, derandomize=True, database=None, deadline=timedelta(seconds=deadline_seconds),
                    suppress_health_check=[HealthCheck.too_slow], print_blob=True)


# ---- scene files -----------------------------------------------------------------------------

def base_scenes():
    """The Cornell box, and the spheres scene with a transformed group holding a mesh file, a
    spot light and a directional light, and an explicit voxel region: every kind of field."""
    box = json.loads((ROOT / "scenes" / "cornell_box.json").read_text())
    spheres = json.loads((ROOT / "scenes" / "cornell_spheres.json").read_text())
    spheres["objects"].append({"name": "Rig", "type": "group", "translation": [0.2, -0.5, 0.1], "rotation": [0, 30, 0],
                               "scale": [0.5, 0.5, 0.5], "children": [
                                   {"name": "Tet", "type": "mesh", "material": "white", "file": "meshes/tetrahedron.obj",
                                    "scale": [0.2, 0.2, 0.2]},
                                   {"name": "Spot", "type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
                                    "intensity": [1, 1, 1], "outer_angle_deg": 40}]})
    spheres["lights"] = [{"name": "Sun", "type": "directional", "direction": [0.2, -1, 0.1], "irradiance": [0.5, 0.5, 0.5]}]
    spheres["voxel_region"] = {"center": [0, 0, 0], "size": 2.2}
    return [box, spheres]


BASES = base_scenes()
TOP_LEVEL_KEYS = set().union(*BASES)  # a mesh file's errors are rooted at its object: objects[i]

# Numbers at the edges: zero and negative zero, subnormals, the float32 and float16 limits,
# the scene limits (1e-6, 1e6), float64 overflow, integers past float and int64 ranges.
EDGE_NUMBERS = [0.5, 0, -0.0, 5e-324, 1e-308, 1e-45, 1.1754944e-38, 9.9e-7, 1e-6, 0.05, -1, 89.0, 179.0, 180,
                65504, 65505, 1e6, 1000000.5, -1e6, 3.4028235e38, 3.5e38, 1e308, -1e308, 2 ** 31, 2 ** 53 + 1, 2 ** 64,
                10 ** 400, 1]
NUMBERS = st.one_of(st.sampled_from(EDGE_NUMBERS), st.floats(-2, 2), st.floats(allow_nan=False, allow_infinity=False),
                    st.integers(-300, 300))
NOT_NUMBERS = st.sampled_from([float("nan"), float("inf"), float("-inf")])  # written as NaN/Infinity tokens
STRINGS = st.one_of(st.text(max_size=4), st.sampled_from(
    ["white", "gold", "box", "group", "sphere", "point", "spot", "directional", "mesh",
     "meshes/box.glb", "meshes/pyramid.ply", "meshes/broken.ply", "meshes/not_a_mesh.obj", "meshes", "/dev/zero",
     "meshes/\x00.obj", "x" * 300]))
VALUES = st.one_of(NUMBERS, NOT_NUMBERS, st.lists(NUMBERS, max_size=4), STRINGS, st.none(), st.booleans(),
                   st.dictionaries(st.sampled_from(["type", "name", "size", "x"]), NUMBERS, max_size=2))


def replacement(draw, value, any_kind):
    """A new value for `value` of its own kind (a number for a number, a vector of as many
    numbers for a vector), or with `any_kind` sometimes anything."""
    if (any_kind and draw(st.integers(0, 4)) == 4) or isinstance(value, bool) or value is None:
        return draw(VALUES)
    if isinstance(value, (int, float)):
        return draw(NUMBERS)
    if isinstance(value, str):
        return draw(STRINGS)
    if isinstance(value, list) and all(isinstance(v, (int, float)) for v in value):
        return draw(st.lists(NUMBERS, min_size=len(value), max_size=len(value)))
    return draw(VALUES)


def paths(document, prefix=()):
    """Every path (tuple of keys and indices) to a value below the top level."""
    items = document.items() if isinstance(document, dict) else enumerate(document) if isinstance(document, list) else ()
    for key, value in items:
        yield prefix + (key,)
        yield from paths(value, prefix + (key,))


def container(document, path):
    for key in path[:-1]:
        document = document[key]
    return document


def _is_value(value):
    """A number, a string or a vector: what a mutation of its own kind replaces."""
    numbers = (int, float)
    return isinstance(value, (*numbers, str)) or (isinstance(value, list) and all(isinstance(v, numbers) for v in value))


@st.composite
def mutated_scenes(draw, structure=True):
    """A base scene with one to three mutations: values of their own kind only, unless
    `structure`, which also changes types, deletes, duplicates and nests."""
    return mutate(draw, copy.deepcopy(draw(st.sampled_from(BASES))), structure, nest=True)


def mutate(draw, document, structure, nest):
    """`document` (parsed JSON) with one to three mutations; `nest`: wrapping a value in scene
    groups is one of them."""
    operations = ["replace"] * 6 + ["delete", "duplicate"] + (["nest"] if nest else [])
    for _ in range(draw(st.integers(1, 3))):
        candidates = [p for p in paths(document) if structure or _is_value(container(document, p)[p[-1]])]
        path = draw(st.sampled_from(candidates))
        parent, key = container(document, path), path[-1]
        operation = draw(st.sampled_from(operations)) if structure else "replace"
        if operation == "replace":
            parent[key] = replacement(draw, parent[key], any_kind=structure)
        elif operation == "delete":
            del parent[key]
        elif operation == "duplicate" and isinstance(parent, list):
            parent.extend([copy.deepcopy(parent[key])] * draw(st.integers(1, 20)))
        elif operation == "nest":  # inside groups of edge transforms
            for _ in range(draw(st.integers(1, 40))):
                parent[key] = {"name": "Nest", "type": "group", "children": [parent[key]],
                               draw(st.sampled_from(["translation", "scale", "rotation"])): draw(st.lists(NUMBERS, min_size=3, max_size=3))}
    return document


def write_document(directory, document):
    """The scene `document` as directory/scene.json, with the test meshes beside it."""
    return write_scene(directory, json.dumps(document))  # Python's json writes NaN and Infinity tokens


def assert_one_line_naming_a_field(line, source):
    """`<file>: <field>: <message>`, the field rooted at a top-level key of a scene, or
    `<file>: unknown field "<key>" ...` for a key the scene's top level does not take."""
    assert "\n" not in line and "Traceback" not in line, line
    prefix = f"{source}: "
    assert line.startswith(prefix), line
    if line[len(prefix):].startswith('unknown field "'):
        return
    field, _, message = line[len(prefix):].partition(": ")
    assert message, line
    root = field.split(".")[0].split("[")[0].split(" ")[0]
    assert root in TOP_LEVEL_KEYS or root == "line", line  # "line L column C" for malformed JSON


def assert_gpu_inputs_finite(scene):
    """What the renderer uploads from an accepted scene is finite in float32."""
    for node, world in scene.drawables():
        assert np.all(np.isfinite(np.frombuffer(gl_bytes(world), "f4")))
        assert np.all(np.isfinite(node.mesh.normals)) and np.all(np.linalg.norm(node.mesh.normals, axis=1) > 0.5)
        emission = node.material.emission
        assert np.all(np.isfinite(np.asarray(emission, "f2"))) and np.all(emission <= np.finfo(np.float16).max)
        for array in (node.mesh.positions, node.mesh.texcoords, node.mesh.tangents):
            assert array is None or np.all(np.isfinite(array))
    for _, light in scene.lights():
        for value in (light.position, light.direction, light.intensity):
            assert np.all(np.isfinite(np.asarray(value, "f4")))
    camera = scene.camera
    assert np.all(np.isfinite(np.asarray(camera.view_matrix(), "f4")))
    assert np.all(np.isfinite(np.asarray(camera.projection_matrix(1.0, 0.01, 100.0), "f4")))
    region = scene.region()
    assert np.isfinite(np.float32(region.size)) and np.float32(region.size) > 0


def assert_loads_with_finite_gpu_inputs_or_fails_with_one_line_naming_a_field(path):
    """The property of a loaded scene file, an overflow or invalid value on the way (any
    warning but a VctWarning) being a failure too."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.simplefilter("ignore", VctWarning)
        try:
            scene = load_scene(path)
        except SceneError as error:
            assert_one_line_naming_a_field(str(error), path)
            return
    assert_gpu_inputs_finite(scene)


@fuzz_settings(examples=300, deadline_seconds=5)
@given(document=mutated_scenes())
def test_mutated_scene_loads_with_finite_gpu_inputs_or_fails_with_one_line_naming_the_field(document):
    with tempfile.TemporaryDirectory() as directory:
        assert_loads_with_finite_gpu_inputs_or_fails_with_one_line_naming_a_field(write_document(directory, document))


def run_vct(args):
    """engine.app.cli.run (main without its warnings filter) in this process: (exit code, stdout,
    stderr), warnings as errors."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            code = run([str(a) for a in args])
        except SystemExit as exit:  # argparse
            code = exit.code
    return code, out.getvalue(), err.getvalue()


def render_and_check(scene_path, directory, options, names_field):
    """Render into `directory` holding an old out.png (and no out.npy); check the property."""
    png, npy = Path(directory) / "out.png", Path(directory) / "out.npy"
    png.write_bytes(b"the previous render")
    before = sorted(Path(directory).iterdir())
    code, _, err = run_vct(["render", scene_path, "--out", png, "--hdr", npy, *options])
    lines = [line for line in err.splitlines() if not line.startswith("vct: warning: ")]
    if code == 0:
        radiance = np.load(npy)
        assert radiance.dtype == np.float32 and np.all(np.isfinite(radiance)), options
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and lines == [], err
        return
    assert code == 2, (code, err)
    assert len(lines) == 1 and lines[0].startswith("vct: error: "), err
    names_field(lines[0][len("vct: error: "):])
    assert sorted(Path(directory).iterdir()) == before and png.read_bytes() == b"the previous render"


@fuzz_settings(examples=60, deadline_seconds=30)
@given(document=mutated_scenes(structure=False), mode=st.sampled_from(["direct", "gi", "albedo", "normal", "voxels"]))
def test_mutated_scene_renders_finite_or_exits_2_naming_the_field_and_changes_no_file(document, mode):
    with tempfile.TemporaryDirectory() as scene_directory, tempfile.TemporaryDirectory() as out_directory:
        path = write_document(scene_directory, document)
        render_and_check(path, out_directory, ["--mode", mode, *SMALL],
                         lambda line: assert_one_line_naming_a_field(line, path))


# ---- mesh files ------------------------------------------------------------------------------

GLTF = two_material_gltf()
GLB_JSON, GLB_BIN = 0x4E4F534A, 0x004E4942


def glb(document, blob):
    """A GLB file of a glTF document and its binary chunk, as written (byteLength and all)."""
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    blob = bytes(blob) + b"\0" * (-len(blob) % 4)
    chunks = struct.pack("<II", len(text), GLB_JSON) + text + struct.pack("<II", len(blob), GLB_BIN) + blob
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def _base_gltf_document():
    document = copy.deepcopy(GLTF.doc)
    document["buffers"][0]["byteLength"] = len(GLTF.blob)
    return document


GLB = glb(_base_gltf_document(), GLTF.blob)
# What a glTF value may be replaced with besides numbers: file names and URIs that name nothing
# readable, a device, a directory, a data URI that is not base64.
GLTF_STRINGS = ["/dev/zero", "meshes", "missing.bin", "data:application/octet-stream;base64,@@", "x" * 300, "\x00",
                "MASK", "BLEND", "KHR_draco_mesh_compression"]


@st.composite
def mutated_gltf_files(draw):
    """(name, bytes) of the base glTF (a hierarchy of two meshes, three materials, two shared
    images, a matrix node) as a GLB whose JSON was mutated, or whose bytes were."""
    if draw(st.booleans()):
        document = mutate(draw, _base_gltf_document(), structure=True, nest=False)
        for path in draw(st.lists(st.sampled_from(list(paths(document))), max_size=2)):
            parent = container(document, path)
            if isinstance(parent[path[-1]], str):
                parent[path[-1]] = draw(st.sampled_from(GLTF_STRINGS))
        return "model.glb", glb(document, GLTF.blob)
    data = bytearray(GLB)
    header = len(GLB) - len(GLTF.blob) - 8  # the JSON chunk and the headers before the binary chunk
    for _ in range(draw(st.integers(1, 8))):
        position = draw(st.one_of(st.integers(0, 27), st.integers(header, header + 8), st.integers(0, len(data) - 1)))
        data[position] = draw(st.integers(0, 255))
    if draw(st.integers(0, 4)) == 0:
        data = data[:draw(st.integers(0, len(data)))]
    return "model.glb", bytes(data)


# Arguments an MTL or OBJ statement may get: numbers at the edges, words that are no numbers,
# texture options, image names that are missing, a device, a directory.
TEXT_ARGUMENTS = [str(n) for n in EDGE_NUMBERS] + ["nan", "inf", "-inf", "1e30", "1e309", "-1", "", "x", "/dev/zero",
                                                   "missing.png", "brick.png", "mask.png", "meshes", "-clamp", "on",
                                                   "-s", "1/1/1", "-2/-1", "0"]
TEXT_STATEMENTS = ["Kd", "Ke", "Ks", "Ns", "d", "Tr", "map_Kd", "map_Ke", "map_d", "newmtl", "usemtl", "mtllib", "v",
                   "vt", "vn", "f"]


@st.composite
def mutated_text(draw, text):
    """`text` (an MTL or OBJ file) with one to three lines changed: an argument replaced, the
    line deleted or duplicated, or a statement added."""
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 3))):
        k = draw(st.integers(0, len(lines) - 1))
        operation = draw(st.sampled_from(["argument"] * 4 + ["delete", "duplicate", "add"]))
        words = lines[k].split()
        if operation == "argument" and len(words) > 1:
            words[draw(st.integers(1, len(words) - 1))] = draw(st.sampled_from(TEXT_ARGUMENTS))
            lines[k] = " ".join(words)
        elif operation == "delete":
            del lines[k]
        elif operation == "duplicate":
            lines[k:k] = [lines[k]] * draw(st.integers(1, 5))
        elif operation == "add":
            arguments = draw(st.lists(st.sampled_from(TEXT_ARGUMENTS), max_size=4))
            lines.insert(k, " ".join([draw(st.sampled_from(TEXT_STATEMENTS)), *arguments]))
        if not lines:
            lines = [""]
    return "\n".join(lines) + "\n"


@st.composite
def mutated_mesh_files(draw):
    """(directory writer, mesh file name): a mutated GLB, or the two-material OBJ with its MTL
    (and their images) mutated."""
    if draw(st.booleans()):
        name, data = draw(mutated_gltf_files())
        return lambda directory: (Path(directory) / name).write_bytes(data), name
    mtl, obj = (draw(mutated_text(MTL)), OBJ) if draw(st.integers(0, 3)) else (MTL, draw(mutated_text(OBJ)))
    return lambda directory: write_obj(directory, obj=obj, mtl=mtl), "two.obj"


@fuzz_settings(examples=300, deadline_seconds=5)
@given(case=mutated_mesh_files())
def test_mutated_mesh_file_loads_with_finite_gpu_inputs_or_fails_with_one_line_naming_the_field(case):
    write, name = case
    with tempfile.TemporaryDirectory() as directory:
        shutil.copytree(DATA, Path(directory) / "meshes")
        write(directory)
        assert_loads_with_finite_gpu_inputs_or_fails_with_one_line_naming_a_field(write_model_scene(directory, name))


@fuzz_settings(examples=30, deadline_seconds=30)
@given(case=mutated_mesh_files(), mode=st.sampled_from(["direct", "gi", "albedo"]))
def test_mutated_mesh_file_renders_finite_or_exits_2_naming_the_field_and_changes_no_file(case, mode):
    write, name = case
    with tempfile.TemporaryDirectory() as scene_directory, tempfile.TemporaryDirectory() as out_directory:
        write(scene_directory)
        path = write_model_scene(scene_directory, name)
        render_and_check(path, out_directory, ["--mode", mode, *SMALL], lambda line: assert_one_line_naming_a_field(line, path))


# ---- command lines ---------------------------------------------------------------------------

EDGE_ARGUMENTS = ["0", "-0", "-1", "1", "2", "8", "9", "16", "17", "32", "64", "65", "512", "16385", "1e3", "0.5",
                  "0.05", "0.0499", "2.01", "1e-300", "1e38", "1e308", "1e309", "nan", "inf", "-inf", "", "x", "10" * 20]
OPTIONS = {"--width": EDGE_ARGUMENTS, "--height": EDGE_ARGUMENTS,
           "--grid": ["16", "32", "0", "-16", "17", "512", "x"],  # larger valid grids: too slow for a fuzz budget
           "--bounces": EDGE_ARGUMENTS, "--bounce-interleave": EDGE_ARGUMENTS, "--mip": EDGE_ARGUMENTS,
           "--cone-step": EDGE_ARGUMENTS, "--cone-offset": EDGE_ARGUMENTS, "--ao-distance": EDGE_ARGUMENTS,
           "--exposure": EDGE_ARGUMENTS, "--mode": ["gi", "ao", "specular", "voxel-normals", "depth", "nope", ""],
           "--tonemap": ["aces", "reinhard", "none", "filmic"]}
# What an error about an option may call it: the option, its setting's name, or the image size.
OPTION_NAMES = {option: {option, option[2:].replace("-", "_")} | ({"size"} if option in ("--width", "--height") else set())
                for option in OPTIONS}
OPTION_NAMES["--mip"] |= {"grid"}  # the mip level is checked against the grid


@st.composite
def mutated_command_lines(draw):
    """Options with edge values, on top of the small defaults; (options, the mutated ones)."""
    chosen = draw(st.lists(st.sampled_from(sorted(OPTIONS)), min_size=1, max_size=3, unique=True))
    options = {"--width": "16", "--height": "16", "--grid": "16", "--mode": "direct"}
    options.update({option: draw(st.sampled_from(OPTIONS[option])) for option in chosen})
    flags = draw(st.lists(st.sampled_from(["--no-direct", "--no-diffuse", "--no-specular"]), unique=True))
    return [word for option, value in options.items() for word in (option, value)] + flags, chosen


@fuzz_settings(examples=40, deadline_seconds=30)
@given(case=mutated_command_lines())
def test_mutated_command_line_renders_finite_or_exits_2_naming_the_option_and_changes_no_file(case):
    options, chosen = case
    names = set().union(*(OPTION_NAMES[option] for option in chosen))

    def names_an_option(line):
        assert any(name in line for name in names), (line, chosen)

    with tempfile.TemporaryDirectory() as directory:
        render_and_check(ROOT / "scenes" / "cornell_box.json", directory, options, names_an_option)


# ---- end to end ------------------------------------------------------------------------------

@fuzz_settings(examples=8, deadline_seconds=60)
@given(document=mutated_scenes(structure=False),
       command_line=st.one_of(st.just((["--mode", "direct", *SMALL], [])), mutated_command_lines()))
def test_mutated_inputs_as_a_real_process_exit_0_or_2_with_one_line_and_no_traceback(document, command_line):
    options, _ = command_line
    with tempfile.TemporaryDirectory() as directory:
        path = write_document(directory, document)
        out = Path(directory) / "out"
        out.mkdir()
        result = subprocess.run([sys.executable, "-m", "engine.app.cli", "render", str(path), "--out", str(out / "x.png"),
                                 "--hdr", str(out / "x.npy"), *options],
                                cwd=ROOT, capture_output=True, text=True, timeout=120)
        assert result.returncode in (0, 2), result.stderr
        if result.returncode == 2:
            assert len(result.stderr.splitlines()) == 1 and result.stderr.startswith("vct: error: "), result.stderr
            assert list(out.iterdir()) == []
        else:
            assert result.stderr == "" and np.all(np.isfinite(np.load(out / "x.npy")))
