"""What a small file claims is checked before memory is spent on it, a decoder's complaints
become vct's one line, and what vct cannot use is named rather than rendered wrong:
- a glTF file's triangles (strips and fans expanded) and its decoded accessors are bounded
  from their counts, a buffer view or not;
- a Radiance map's size is read as its decoder reads it; a truncated OpenEXR is one line
  with nothing printed before it; textures are read only in the formats a renderer needs;
- vertex colours are held to the albedo's range; geometry far away still draws;
- a signal handler installed outside Python is left as it was.
"""
import io
import json
import signal
import warnings

import numpy as np
import pytest
from PIL import Image

import engine
from engine.app import cli
from engine.core.limits import MAX_DECODED_BYTES, MAX_FILE_TRIANGLES
from test_cli import CORNELL, assert_one_line_error, vct  # tests/ is on sys.path under pytest
from test_mesh_files import Gltf, png, textured_quad

SMALL = ["--width", "16", "--height", "16", "--grid", "16"]


def bufferless(tmp_path, index_count, primitives=1, mode=5):
    """A 1 kB glTF whose primitives index a position accessor with `index_count` indices
    and neither accessor has a buffer view (legal: both read as zeros)."""
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": list(range(primitives))}],
           "nodes": [{"mesh": k} for k in range(primitives)],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]} for _ in range(primitives)],
           "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3", "max": [0, 0, 0], "min": [0, 0, 0]},
                         {"componentType": 5125, "count": index_count, "type": "SCALAR"}]}
    path = tmp_path / "bufferless.gltf"
    path.write_text(json.dumps(doc))
    return path


def test_strip_indices_that_would_expand_past_the_triangle_limit_are_refused_from_their_count(tmp_path):
    """16.7 M strip indices in a 1 kB file: refused naming the primitive, before any triangle
    is made; so are three primitives whose strips share one accessor and reach the limit
    together."""
    result = vct("render", bufferless(tmp_path, 2 * MAX_FILE_TRIANGLES), "--out", tmp_path / "x.png", *SMALL)
    assert_one_line_error(result, "meshes[0].primitives[0]", f"more than {MAX_FILE_TRIANGLES} triangles")
    result = vct("render", bufferless(tmp_path, MAX_FILE_TRIANGLES // 2, primitives=3), "--out", tmp_path / "x.png", *SMALL)
    assert_one_line_error(result, "meshes[2].primitives[0]", "triangles")
    assert not (tmp_path / "x.png").exists()


def test_accessors_without_buffer_views_are_bounded_together(tmp_path, monkeypatch):
    """Each accessor read as zeros counts against the file's decoded bytes, once."""
    monkeypatch.setattr("engine.formats.gltf.container.MAX_DECODED_BYTES", 2 ** 20)
    with pytest.raises(engine.SceneError, match=r"accessors\[1\].count: the file's accessors would decode to more"):
        engine.load_scene(bufferless(tmp_path, 2 ** 18 + 1, mode=4))
    assert MAX_DECODED_BYTES == 2 ** 30


def rgbe(size_line, pixels=b""):
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + size_line + b"\n" + pixels


def test_a_radiance_map_is_sized_as_its_decoder_reads_it(tmp_path):
    """A size line with two spaces (which the decoder reads) and a small, fake one hidden in
    the pixels: refused from the real one, before decoding."""
    path = tmp_path / "sky.hdr"
    path.write_bytes(rgbe(b"-Y  30000 +X  30000", b"\n\n-Y 2 +X 2\n" + bytes(64)))
    result = vct("render", CORNELL, "--environment", path, "--out", tmp_path / "x.png", *SMALL)
    assert_one_line_error(result, "sky.hdr", "30000x30000 pixels")
    path.write_bytes(rgbe(b"-Y 2 +X 2", bytes([128, 128, 128, 129]) * 4))
    result = vct("render", CORNELL, "--environment", path, "--out", tmp_path / "x.png", *SMALL)
    assert result.returncode == 0, result.stderr


def test_a_truncated_openexr_is_one_line_with_nothing_printed_before_it(tmp_path):
    import OpenEXR

    whole = tmp_path / "whole.exr"
    OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage},
                 {"RGB": np.ones((64, 64, 3), np.float32)}).write(str(whole))
    data = whole.read_bytes()
    for cut in (0.3, 0.8):
        path = tmp_path / "cut.exr"
        path.write_bytes(data[:int(len(data) * cut)])
        result = vct("render", CORNELL, "--environment", path, "--out", tmp_path / "x.png", *SMALL)
        assert_one_line_error(result, "cut.exr", "cannot decode OpenEXR")
        assert result.stdout == ""


def test_a_texture_in_a_format_read_through_an_interpreter_is_refused(tmp_path):
    """An EPS image (Pillow hands it to Ghostscript where it is installed) is not decoded:
    the texture's error names the formats vct reads."""
    eps = b"%!PS-Adobe-3.0 EPSF-3.0\n%%BoundingBox: 0 0 2 2\n0 0 moveto 2 2 lineto stroke\nshowpage\n"
    g = textured_quad()
    g.doc["images"][0] = {"bufferView": g.view(eps), "mimeType": "image/png"}
    path = g.write(tmp_path / "eps.gltf")
    with pytest.raises(engine.SceneError, match="not one of the formats vct reads: PNG, JPEG"):
        engine.load_scene(path)
    assert Image.open(io.BytesIO(png(np.zeros((2, 2, 3), np.uint8)))).format == "PNG"


def test_vertex_colours_beyond_one_are_clamped_to_the_albedo_range_with_a_warning(tmp_path):
    """COLOR_0 of 100 would make a surface reflect 80 times its light: it is held to 1."""
    g = Gltf()
    quad = g.quad()
    quad["attributes"]["COLOR_0"] = g.accessor(np.full((4, 3), 100.0, np.float32))
    g.doc["meshes"].append({"primitives": [quad]})
    g.doc["nodes"].append({"mesh": 0})
    g.doc["scenes"][0]["nodes"] = [0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = engine.load_scene(g.write(tmp_path / "bright.gltf"))
    (node,) = [node for node, _ in scene.drawables()]
    assert node.mesh.colors.max() == 1.0
    assert len(caught) == 1 and "COLOR_0" in str(caught[0].message) and "accessors[" in str(caught[0].message)


def test_a_surface_100_km_away_is_drawn(tmp_path):
    """A quad 60 km wide, 100 km down the view: it fills the part of the view it subtends."""
    scene = {"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "vertical_fov_deg": 60, "width": 32, "height": 32},
             "materials": {"m": {"albedo": [0.8, 0.8, 0.8]}},
             "objects": [{"name": "Far", "type": "quad", "material": "m",
                          "vertices": [[-3e4, -3e4, -1e5], [3e4, -3e4, -1e5], [3e4, 3e4, -1e5], [-3e4, 3e4, -1e5]]}]}
    path = tmp_path / "far.json"
    path.write_text(json.dumps(scene))
    with engine.Renderer(32, 32) as r:
        albedo = r.render(engine.load_scene(path), mode="albedo")
    covered = (albedo[..., 0] > 0.7).mean()
    assert covered == pytest.approx((0.3 / np.tan(np.radians(30))) ** 2, abs=0.05)


def test_a_signal_handler_installed_outside_python_is_left_in_place(tmp_path, monkeypatch):
    """signal.getsignal says None for a handler a native host installed: vct leaves that
    signal alone instead of failing to put None back when the command ends."""
    native = {signal.SIGHUP}
    real_getsignal, real_signal, calls = signal.getsignal, signal.signal, []
    monkeypatch.setattr(cli.signal, "getsignal", lambda number: None if number in native else real_getsignal(number))

    def recording_signal(number, action):
        calls.append((number, action))
        return real_signal(number, action)

    monkeypatch.setattr(cli.signal, "signal", recording_signal)
    assert cli.main(["render", str(CORNELL), "--out", str(tmp_path / "x.png"), "--quiet", *SMALL]) == 0
    assert calls and all(number not in native and action is not None for number, action in calls)
