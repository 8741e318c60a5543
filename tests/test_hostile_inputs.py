"""Files a scene points to keep the scene file's promises, and every exit is a clean one.

Facts, family by family:
- files: every file a scene, a glTF or an MTL names is read only if it is a regular file
  within its size (a device, a pipe or an oversized file is one line naming the scene, the
  object, the file and the element, at once); images decode only once their header fits the
  pixel limits; an accessor's count times its element size must fit what it reads;
- vertex data: non-finite or out-of-range glTF positions, normals and texture coordinates,
  zero-length normals and strides shorter than an element are refused with the accessor
  named; an OBJ's bad triangles are dropped with one warning for the file;
- one set of limits: a glTF's or an MTL's nodes and materials are held to the scene file's
  limits (world scale, reach, nesting depth counted from the scene's top level, emission);
- exits: SIGTERM, SIGHUP and SIGINT remove the temporary files of outputs being written and
  exit with 128 + the signal; a closed or full stdout costs only the report; an output that
  is one of the inputs is refused; an error is one line, whatever the paths in it hold;
- the Python API raises VctError naming the argument for bad levels, types and use after
  close.
"""
import json
import os
import signal
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import engine
from engine import SceneError, ShaderError, VctError, VctWarning, load_scene
from engine.app.cli import main
from engine.core.limits import MAX_DEPTH, MAX_FILE_BYTES, MAX_IMAGE_PIXELS, MAX_INCLUDE_DEPTH
from engine.gpu.shaders import preprocess
from conftest import interruptible
from test_cli import CORNELL, assert_one_line_error, vct  # tests/ is on sys.path under pytest
from test_mesh_files import PAINTING, TEXTURE, png, textured_quad, write_model_scene, write_obj

ROOT = Path(__file__).resolve().parent.parent
MODEL = 'objects[0] "Model".file'
SMALL = ["--mode", "direct", "--width", "16", "--height", "16"]


def load_error(scene):
    """The one-line message of the SceneError that loading `scene` raises."""
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{scene}: "), message
    return message


def model_gltf(directory, change=None, suffix=".gltf"):
    """A scene loading model.gltf (a textured quad, its buffer in model.bin) after `change`."""
    g = textured_quad()
    if change:
        change(g)
    g.write(Path(directory) / f"model{suffix}")
    return write_model_scene(directory, f"model{suffix}")


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_saying(width, height):
    """A valid PNG that says it is width x height pixels but holds only a few bytes of them."""
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(b"\0" * 64))
            + chunk(b"IEND", b""))


# ---- files a scene points to -----------------------------------------------------------------

def _device(directory):
    return "/dev/zero"


def _pipe(directory):
    os.mkfifo(Path(directory) / "pipe")
    return "pipe"


def _oversized(directory):
    with open(Path(directory) / "huge", "wb") as f:
        f.truncate(MAX_FILE_BYTES + 1)  # sparse: nothing is written to disk
    return "huge"


def _gltf_buffer(directory, name):
    scene = model_gltf(directory)
    document = json.loads((Path(directory) / "model.gltf").read_text())
    document["buffers"][0]["uri"] = name
    (Path(directory) / "model.gltf").write_text(json.dumps(document))
    return scene, ["model.gltf: buffers[0].uri", f'"{name}"']


def _gltf_image(directory, name):
    def change(g):
        g.doc["images"][0] = {"uri": name}
    return model_gltf(directory, change), [f"model.gltf: {TEXTURE}: images[0]", f'"{name}"']


def _mtllib(directory, name):
    write_obj(directory)
    (Path(directory) / "two.obj").write_text((Path(directory) / "two.obj").read_text().replace("two.mtl", name))
    return write_model_scene(directory, "two.obj"), [f'two.obj: mtllib "{name}"']


def _map_kd(directory, name):
    write_obj(directory)
    (Path(directory) / "two.mtl").write_text((Path(directory) / "two.mtl").read_text().replace("brick.png", name))
    return write_model_scene(directory, "two.obj"), ["two.mtl: line ", "(map_Kd)", f'"{name}"']


def _mesh_file(directory, name):
    return write_model_scene(directory, name), [MODEL, name]


NAMED_BY = {"glTF buffer uri": _gltf_buffer, "glTF image uri": _gltf_image, "OBJ mtllib": _mtllib,
            "MTL map_Kd": _map_kd, "scene mesh file": _mesh_file}
NAMING = {"a device": (_device, "not a regular file"), "a pipe": (_pipe, "not a regular file"),
          "a file over 256 MiB": (_oversized, "larger than 256 MiB")}


@pytest.mark.parametrize("named_by", NAMED_BY)
@pytest.mark.parametrize("naming", NAMING)
def test_a_device_a_pipe_or_an_oversized_file_named_anywhere_is_one_line_naming_it_and_is_not_read(
        tmp_path, named_by, naming):
    make_target, problem = NAMING[naming]
    scene, mentions = NAMED_BY[named_by](tmp_path, make_target(tmp_path))
    message = load_error(scene)
    for mention in [*mentions, problem]:
        assert mention in message, message


@pytest.mark.parametrize("name", ["model.zip", "model.tar.gz", "model.bz2", "model"])
def test_a_mesh_file_that_is_an_archive_or_of_no_mesh_format_is_refused(tmp_path, name):
    """trimesh would decompress an archive without a bound (a zip bomb)."""
    (tmp_path / name).write_bytes(b"PK\x03\x04 not really")
    assert f"{MODEL}: {name}: not a mesh format vct reads" in load_error(write_model_scene(tmp_path, name))


def test_an_image_whose_header_says_more_pixels_than_allowed_is_refused_before_it_is_decoded(tmp_path):
    """13000 x 13000 pixels (2.5 GB decoded), said by a PNG of a few hundred bytes."""
    def change(g):
        g.doc["images"][0] = {"bufferView": g.view(png_saying(13000, 13000)), "mimeType": "image/png"}
    message = load_error(model_gltf(tmp_path, change))
    assert f"{TEXTURE}: images[0]" in message and f"13000x13000 pixels, more than {MAX_IMAGE_PIXELS}" in message


def test_the_images_of_a_scene_share_one_pixel_budget(tmp_path, monkeypatch):
    """Two distinct 2x3 images fit a budget of 12 pixels, not one of 11: the second is named."""
    def change(g):
        other = g.texture(g.image(png(PAINTING[::-1].copy())))
        g.doc["materials"][0]["emissiveTexture"] = {"index": other}
    scene = model_gltf(tmp_path, change)
    monkeypatch.setattr("engine.formats.input_files.MAX_INPUT_PIXELS", 12)
    load_scene(scene)
    monkeypatch.setattr("engine.formats.input_files.MAX_INPUT_PIXELS", 11)
    assert "materials[0].emissiveTexture: images[1]: 2x3 pixels" in load_error(scene)


def test_the_files_of_a_scene_share_one_size_budget(tmp_path, monkeypatch):
    scene = model_gltf(tmp_path)
    total = sum(f.stat().st_size for f in (scene, tmp_path / "model.gltf", tmp_path / "model.bin"))
    monkeypatch.setattr("engine.formats.input_files.MAX_INPUT_BYTES", total)
    assert len(load_scene(scene).files) == 3
    monkeypatch.setattr("engine.formats.input_files.MAX_INPUT_BYTES", total - 1)
    assert "model.gltf: buffers[0].uri" in load_error(scene)


def test_an_accessor_of_more_elements_than_a_buffer_holds_is_refused_without_allocating_them(tmp_path):
    """No bufferView: an accessor of zeros 1e12 elements long would be 10.9 TiB."""
    def change(g):
        index = g.add("accessors", {"componentType": 5126, "count": 10 ** 12, "type": "VEC3"})
        g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = index
    message = load_error(model_gltf(tmp_path, change))
    assert "accessors[" in message and ".count: 1000000000000 elements of 12 bytes" in message


def test_a_byte_stride_shorter_than_an_element_is_refused_naming_the_buffer_view(tmp_path):
    def change(g):
        position = g.doc["accessors"][g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
        g.doc["bufferViews"][position["bufferView"]]["byteStride"] = 4
    assert "byteStride: 4 bytes, less than the 12 of an element" in load_error(model_gltf(tmp_path, change))


def test_a_bench_reference_that_is_a_pipe_exits_2_at_once(tmp_path):
    os.mkfifo(tmp_path / "reference.npy")
    result = vct("bench", CORNELL, "--grids", "16", "--frames", "1", "--warmup", "0", "--width", "16", "--height", "16",
                 "--reference", tmp_path / "reference.npy")
    assert_one_line_error(result, "--reference", "not a regular file")


def test_includes_nested_deeper_than_the_limit_are_one_error_naming_the_file_and_line(tmp_path):
    (tmp_path / "main.comp").write_text('#version 450 core\n#include "chain0.glsl"\n')
    for k in range(5000):
        (tmp_path / f"chain{k}.glsl").write_text(f'// link {k}\n#include "chain{k + 1}.glsl"\n')
    (tmp_path / "chain5000.glsl").write_text("\n")
    with pytest.raises(ShaderError) as info:
        preprocess("main.comp", root=tmp_path)
    last = MAX_INCLUDE_DEPTH - 1
    assert str(info.value) == f"glsl/chain{last}.glsl:2: error: #include nests more than {MAX_INCLUDE_DEPTH} files deep"


def test_a_glsl_file_that_is_a_pipe_is_an_error_not_a_hang(tmp_path):
    os.mkfifo(tmp_path / "main.comp")
    with pytest.raises(ShaderError, match="glsl/main.comp: error: cannot read \\(not a regular file\\)"):
        preprocess("main.comp", root=tmp_path)


# ---- vertex data -----------------------------------------------------------------------------

BAD_VALUES = {"NaN": np.nan, "infinity": np.inf, "1e30": 1e30}


@pytest.mark.parametrize("attribute", ["POSITION", "NORMAL", "TEXCOORD_0"])
@pytest.mark.parametrize("value", BAD_VALUES)
def test_gltf_vertex_data_that_is_not_finite_or_out_of_range_is_refused_naming_the_accessor(tmp_path, attribute, value):
    accessor = {}

    def change(g):
        attributes = g.doc["meshes"][0]["primitives"][0]["attributes"]
        data = np.array(g.doc["accessors"][attributes[attribute]]["count"] * [[0.0, 0.0, 1.0][:3 if attribute != "TEXCOORD_0" else 2]])
        data[2, 0] = BAD_VALUES[value]
        accessor["index"] = attributes[attribute] = g.accessor(data.astype(np.float32))
    message = load_error(model_gltf(tmp_path, change))
    assert f"accessors[{accessor['index']}]: (meshes[0].primitives[0].attributes.{attribute}) element 2 is" in message
    assert "finite and within +-1e+06" in message


def test_a_gltf_normal_of_zero_length_is_refused(tmp_path):
    def change(g):
        attributes = g.doc["meshes"][0]["primitives"][0]["attributes"]
        attributes["NORMAL"] = g.accessor(np.array([[0, 0, 1], [0, 0, 1], [0, 0, 0], [0, 0, 1]], np.float32))
    assert "attributes.NORMAL) element 2 is [0.0, 0.0, 0.0]: a normal must have unit length" in load_error(
        model_gltf(tmp_path, change))


def test_gltf_normals_are_scaled_to_unit_length(tmp_path):
    def change(g):
        attributes = g.doc["meshes"][0]["primitives"][0]["attributes"]
        attributes["NORMAL"] = g.accessor(np.tile([0.0, 0.0, 3.0], (4, 1)).astype(np.float32))
    (node, _), = load_scene(model_gltf(tmp_path, change)).drawables()
    np.testing.assert_allclose(node.mesh.normals, np.tile([0.0, 0.0, 1.0], (4, 1)))


def test_obj_triangles_with_bad_vertex_data_are_dropped_with_one_warning_line_for_the_file(tmp_path):
    (tmp_path / "bad.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 inf 0\nv 1e30 0 0\nvt 0 0\nvt 1 0\nvt nan 0\n"
                                      "f 1/1 2/2 3/2\nf 1/1 2/2 4/2\nf 1/1 5/2 3/2\nf 1/1 2/2 3/3\n")
    scene = write_model_scene(tmp_path, "bad.obj")
    with pytest.warns(VctWarning, match="bad.obj: 3 triangles dropped") as record:
        (node, _), = load_scene(scene).drawables()
    assert len(record) == 1 and len(node.mesh.indices) == 1
    result = vct("render", scene, "--out", tmp_path / "x.png", *SMALL)
    assert result.returncode == 0 and result.stderr.startswith("vct: warning: bad.obj: 3 triangles dropped")
    assert len(result.stderr.splitlines()) == 1


# ---- one set of limits -----------------------------------------------------------------------

def _one_node_gltf(directory, node_changes, extra_nodes=()):
    """model.gltf: the textured quad under node "Quad" (with `node_changes`), below `extra_nodes`
    (each a parent of the one before; the last is the root)."""
    def change(g):
        g.doc["nodes"][0].update(name="Quad", **node_changes)
        for k, parent in enumerate(extra_nodes):
            g.doc["nodes"].append({**parent, "children": [k]})
        g.doc["scenes"][0]["nodes"] = [len(g.doc["nodes"]) - 1]
    return model_gltf(directory, change)


GLTF_NODE_CASES = {
    "a scale of zero": ({"scale": [1, 0, 1]}, (), 'node "Quad".scale', "scales by 0..1"),
    "nested translations beyond 1e6 m": ({"translation": [9e5, 0, 0]}, [{"name": "Far", "translation": [9e5, 0, 0]}],
                                         'node "Quad"', "reaches 1.8e+06 m"),
    "a chain 5000 nodes deep": ({}, [{}] * 5000, "nodes[", f"nests more than {MAX_DEPTH} levels deep"),
    "a quaternion of no length": ({"rotation": [0, 0, 0, 1e-300]}, (), "nodes[0].rotation", "unit quaternion"),
}


@pytest.mark.parametrize("case", GLTF_NODE_CASES)
def test_gltf_nodes_are_held_to_the_scene_files_limits(tmp_path, case):
    changes, parents, field, problem = GLTF_NODE_CASES[case]
    message = load_error(_one_node_gltf(tmp_path, changes, parents))
    assert f"{MODEL}: model.gltf: {field}" in message and problem in message, message


def test_a_gltf_node_with_two_parents_is_refused_so_a_file_cannot_multiply_its_nodes(tmp_path):
    """Each node of 30 lists the next one twice: 2^30 nodes if read as a tree."""
    def change(g):
        for k in range(30):
            g.doc["nodes"].append({"children": [len(g.doc["nodes"]) - 1] * 2})
        g.doc["scenes"][0]["nodes"] = [len(g.doc["nodes"]) - 1]
    assert "has more than one parent" in load_error(model_gltf(tmp_path, change))


def test_nesting_depth_counts_the_scenes_levels_and_the_files_together(tmp_path):
    """A mesh object 30 groups deep holding a glTF three nodes deep: 33 levels."""
    scene = _one_node_gltf(tmp_path, {}, [{"name": "Middle"}, {"name": "Top"}])
    data = json.loads(scene.read_text())
    objects = data["objects"][0]
    for level in range(MAX_DEPTH - 3):
        objects = {"name": f"Level {level}", "type": "group", "children": [objects]}
    data["objects"] = [objects]
    scene.write_text(json.dumps(data))
    message = load_error(scene)
    assert 'model.gltf: node "Quad"' in message and "the scene's levels above it counted in" in message


def _scene_emission(directory, value):
    scene = write_model_scene(directory, "unused.obj")
    data = json.loads(scene.read_text())
    data["materials"]["glow"] = {"emission": [value, 0, 0]}
    data["objects"] = [{"name": "Glow", "type": "box", "material": "glow", "size": [1, 1, 1]}]
    scene.write_text(json.dumps(data))
    return scene, "materials.glow.emission[0]"


def _gltf_emission(directory, value):
    def change(g):
        g.doc["materials"][0].update(emissiveFactor=[1, 0, 0], extensions={
            "KHR_materials_emissive_strength": {"emissiveStrength": value}})
    return model_gltf(directory, change), "materials[0].emissiveFactor x extensions.KHR_materials_emissive_strength"


def _mtl_emission(directory, value):
    write_obj(directory)
    (Path(directory) / "two.mtl").write_text((Path(directory) / "two.mtl").read_text().replace("Ke 2 1 0.5", f"Ke {value} 0 0"))
    return write_model_scene(directory, "two.obj"), 'two.mtl: newmtl "Glow": line 8 (Ke)'


@pytest.mark.parametrize("source", ["scene file", "glTF", "MTL"])
def test_emission_above_half_floats_is_refused_whichever_file_the_material_comes_from(tmp_path, source):
    """65504 W/(m^2 sr), the largest half float, is the bound of a scene material, a glTF's
    emissiveFactor x emissiveStrength and an MTL's Ke alike."""
    make = {"scene file": _scene_emission, "glTF": _gltf_emission, "MTL": _mtl_emission}[source]
    for directory in ("fits", "over"):
        (tmp_path / directory).mkdir()
    load_scene(make(tmp_path / "fits", 65504)[0])
    scene, field = make(tmp_path / "over", 1e6)
    message = load_error(scene)
    assert field in message and "65504" in message, message


# ---- exits -----------------------------------------------------------------------------------

SIGNALLED_RENDER = """
import os, signal, sys
import engine.formats.output
from engine.app.cli import main

def png_writer(pixels):
    def write(f):
        f.write(b"half a PNG")
        f.flush()
        os.kill(os.getpid(), signal.{signal})
        f.write(b"the other half")
    return write

engine.formats.output.png_writer = png_writer
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_signal_while_outputs_are_written_removes_their_temporary_files_and_exits_128_plus_it(tmp_path, name):
    out = tmp_path / "out"
    out.mkdir()
    (out / "x.png").write_bytes(b"the previous render")
    result = subprocess.run([sys.executable, "-c", SIGNALLED_RENDER.replace("{signal}", name), "render", CORNELL,
                             "--out", out / "x.png", "--hdr", out / "x.npy", *SMALL],
                            cwd=ROOT, capture_output=True, text=True, timeout=120, preexec_fn=interruptible)
    assert result.returncode == 128 + getattr(signal, name), result.stderr
    assert result.stderr == ""
    assert sorted(p.name for p in out.iterdir()) == ["x.png"] and (out / "x.png").read_bytes() == b"the previous render"


def test_a_closed_stdout_loses_only_the_report(tmp_path):
    """The reader of stdout is gone before vct reports what it wrote."""
    process = subprocess.Popen([sys.executable, "-m", "engine.app.cli", "render", CORNELL, "--out", tmp_path / "x.png",
                                *SMALL], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    process.stdout.close()
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 0 and stderr == b""
    assert (tmp_path / "x.png").read_bytes()[:4] == b"\x89PNG"


def test_a_full_stdout_loses_only_the_report(tmp_path):
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "engine.app.cli", "render", CORNELL, "--out", tmp_path / "x.png",
                                 *SMALL], cwd=ROOT, stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr == ""
    assert (tmp_path / "x.png").read_bytes()[:4] == b"\x89PNG"


def test_an_output_that_is_one_of_the_scenes_files_is_refused_and_left_as_it_was(tmp_path):
    scene = model_gltf(tmp_path)
    os.link(tmp_path / "model.bin", tmp_path / "link.png")
    files = {path: path.read_bytes() for path in (scene, tmp_path / "model.gltf", tmp_path / "model.bin")}
    for output, read in ((scene, scene), (tmp_path / "link.png", tmp_path / "model.bin")):
        result = vct("render", scene, "--out", output, *SMALL)
        assert_one_line_error(result, f"{output}: --out: is a file this command reads ({read})")
    assert all(path.read_bytes() == data for path, data in files.items())


def test_a_bench_json_that_is_the_reference_is_refused(tmp_path):
    reference = tmp_path / "reference.npy"
    np.save(reference, np.ones((16, 16, 3), np.float32))
    result = vct("bench", CORNELL, "--grids", "16", "--frames", "1", "--warmup", "0", "--width", "16", "--height", "16",
                 "--reference", reference, "--json", reference)
    assert_one_line_error(result, "--json: is a file this command reads")
    assert np.load(reference).shape == (16, 16, 3)


def test_control_characters_in_a_path_are_escaped_so_the_error_is_one_line(tmp_path):
    result = vct("render", tmp_path / "no\nsuch\x1b.json", "--out", tmp_path / "x.png")
    assert_one_line_error(result, "no\\nsuch\\x1b.json: cannot read scene file (file not found)")


def test_a_library_warning_on_the_way_to_an_error_is_not_printed(tmp_path, monkeypatch, capsys):
    def load_scene_warning(path, **options):
        np.float32(1e39)  # numpy: overflow encountered in cast
        raise SceneError("the error", source=path)
    monkeypatch.setattr("engine.formats.scene_file.load_scene", load_scene_warning)
    with np.errstate(all="warn"):
        assert main(["render", str(CORNELL), "--out", str(tmp_path / "x.png")]) == 2
    assert capsys.readouterr().err == f"vct: error: {CORNELL}: the error\n"


# ---- the Python API --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def voxelized():
    with engine.Renderer(16, 16) as r:
        r.render(load_scene(CORNELL), grid=16, bounces=1)
        yield r


@pytest.mark.parametrize("level", [-1, 5, 1.0, True, "1"])
def test_voxels_at_a_level_the_grid_does_not_have_raise_vct_error_naming_the_level(voxelized, level):
    with pytest.raises(VctError, match=f"^level: must be a whole number in 0..4 for grid 16, got {level!r}$"):
        voxelized.voxels(level=level)


def test_voxels_of_an_unknown_volume_raise_vct_error_naming_it(voxelized):
    with pytest.raises(VctError, match="^name: must be one of radiance, normal, albedo, gathered, got 'colour'$"):
        voxelized.voxels("colour")


def test_voxels_at_the_top_level_are_one_voxel(voxelized):
    assert voxelized.voxels(level=4).shape == (1, 1, 1, 4)


@pytest.mark.parametrize("setting, value, kind", [
    ("grid", 64.0, "a whole number"), ("bounces", True, "a whole number"), ("exposure", "1", "a number"),
    ("direct", 1, "True or False"), ("mode", None, "a string"), ("shadow_map_size", 4096, "in 16..1024"),
    ("diffuse_cones", "wide", "one of six, tiled, got 'wide'"),
])
def test_settings_of_the_wrong_type_or_range_raise_vct_error_naming_the_setting(setting, value, kind):
    with pytest.raises(VctError, match=f"^{setting}: must be {kind}"):
        engine.RenderSettings(**{setting: value}).validate()


def test_numpy_numbers_are_settings_of_their_kind():
    settings = engine.RenderSettings(grid=np.int64(32), exposure=np.float32(2)).validate()
    assert type(settings.grid) is int and settings.grid.bit_length() == 6 and type(settings.exposure) is float


@pytest.mark.parametrize("size, name", [(("256", 256), "width"), ((256, 2.5), "height"), ((0, 16), "width")])
def test_an_image_size_that_is_not_a_positive_whole_number_raises_vct_error_naming_it(size, name):
    with pytest.raises(VctError, match=f"^{name}: must be a positive whole number"):
        engine.Renderer(*size)


def test_a_closed_renderer_raises_vct_error_naming_the_method():
    renderer = engine.Renderer(16, 16)
    renderer.close()
    scene = load_scene(CORNELL)
    for call, name in ((lambda: renderer.render(scene), "render"), (renderer.radiance, "radiance"),
                       (renderer.voxels, "voxels"), (lambda: renderer.resize(8, 8), "resize")):
        with pytest.raises(VctError, match=f"^Renderer.{name}: the renderer is closed"):
            call()


def test_render_of_something_that_is_not_a_scene_raises_vct_error_naming_it(voxelized):
    with pytest.raises(VctError, match="^scene: must be an engine Scene"):
        voxelized.render("scenes/cornell_box.json")
