"""GLSL sources: #include expansion, error lines mapped to the real file, hot reload that keeps
the last good program, and constants defined once for host and shaders."""
import re
import shutil

import pytest

import engine
from engine.core import constants
from engine.gpu.shaders import GLSL_ROOT, ProgramLibrary, preprocess


@pytest.fixture
def glsl_copy(tmp_path):
    root = tmp_path / "glsl"
    shutil.copytree(GLSL_ROOT, root)
    return root


def test_includes_are_expanded_once_with_line_directives():
    source = preprocess("lighting/shade_lights.frag")
    assert "#include" not in source.text
    assert source.text.startswith("#version 450")
    assert source.files[0] == "glsl/lighting/shade_lights.frag"
    assert "glsl/lib/lights.glsl" in source.files and "engine/core/constants.py" in source.files
    # engine_constants.glsl is pulled in by several libraries but expanded once.
    assert source.text.count("#define MAX_LIGHTS") == 1


def test_constants_header_matches_the_python_values():
    header = constants.glsl_header()
    for name, unit in constants.TEXTURE_UNIT.items():
        assert f"#define TEX_{name} {unit}" in header
    assert f"#define MAX_LIGHTS {constants.MAX_LIGHTS}" in header
    directions, weights, _ = constants.diffuse_cones()
    assert f"#define DIFFUSE_CONE_COUNT {len(weights)}" in header


def test_shared_enums_and_struct_layouts_come_from_the_python_tables():
    header = constants.glsl_header()
    for group, names in constants.SHADER_ENUMS.items():
        for name, value in names.items():
            assert f"#define {group}_{name.upper()} {value}" in header
    for name, members in constants.GLSL_STRUCTS.items():
        assert constants.struct_dtype(name).itemsize == 16 * sum((4 if kind == "mat4" else 1) * (count[0] if count else 1)
                                                                 for kind, _, *count in members)
    # No shader defines them again: each lives in engine/core/constants.py alone.
    for path in GLSL_ROOT.rglob("*.*"):
        text = path.read_text()
        assert not re.search(r"#define (TONEMAP|OUTPUT|VIEW|SHOW|VOXELIZE|MAP)_[A-Z_]+ \d", text), path
        assert not re.search(r"^struct (Light|ShadowView|EmitterTriangle|EmitterPatch|DrawRecord|MaterialRecord|Cluster|DrawView)\b",
                             text, re.M), path
    covered = [p for p in GLSL_ROOT.rglob("*.*") if "buffer CoveredVoxels" in p.read_text()]
    assert [p.name for p in covered] == ["covered_voxels.glsl"]


def test_a_program_that_binds_two_resources_to_one_unit_is_refused_naming_both(glsl_copy):
    shader = glsl_copy / "voxel_grid/clear_cells.comp"
    lines = shader.read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if "IMG_FACES_OUT" in line)
    lines.insert(at + 1, "layout(binding = IMG_INSPECT_OUT, rgba16f) uniform writeonly image3D also_out;")
    shader.write_text("\n".join(lines) + "\n")
    assert constants.IMAGE_UNIT["INSPECT_OUT"] == constants.IMAGE_UNIT["FACES_OUT"]
    with pytest.raises(engine.ShaderError) as error:
        engine.Renderer(16, 16, glsl_root=glsl_copy)
    message = str(error.value)
    assert message.startswith(f"glsl/voxel_grid/clear_cells.comp:{at + 2}: error: IMG_INSPECT_OUT"), message
    assert f"IMG_FACES_OUT is (glsl/voxel_grid/clear_cells.comp:{at + 1})" in message


def test_a_program_that_reads_a_resource_its_pass_does_not_declare_is_refused(glsl_copy):
    """Each pass declares what its programs bind (ProgramLibrary.program reads/writes): a
    shader edited to sample the face views, which light injection does not declare, fails to
    build with a line naming the file and the binding."""
    shader = glsl_copy / "inject/inject_direct_light.comp"
    text = shader.read_text().replace("void main() {", "layout(binding = TEX_VOXEL_FACES) uniform sampler3D faces_seen;\n"
                                      "void main() {\n    if (texelFetch(faces_seen, ivec3(0), 0).a < 0.0) return;", 1)
    shader.write_text(text)
    with pytest.raises(engine.ShaderError) as error:
        engine.Renderer(16, 16, glsl_root=glsl_copy)
    assert str(error.value) == "glsl/inject/inject_direct_light.comp: error: uses TEX_VOXEL_FACES, which its pass does not declare"


def test_a_dispatch_binds_exactly_what_its_program_declares():
    """A dispatch takes its resources by binding name in one mapping, checked against what its
    pass declared for the program: one it does not declare, or one it declares and is not
    given, is refused by name before anything is bound or dispatched."""
    with engine.Renderer(16, 16) as r, r.ctx:
        handle = ProgramLibrary(r.ctx).compute("voxel_grid/size_segment.comp", reads=("SSBO_COUNTED",), writes=("SSBO_SEGMENTS",))
        counted, segments = r.ctx.buffer(data=bytes(64)), r.ctx.buffer(data=bytes(64))
        handle.run(1, SSBO_COUNTED=counted, SSBO_SEGMENTS=segments)
        with pytest.raises(ValueError, match=r"bound \[\] it does not declare, not bound \['SSBO_SEGMENTS'\]"):
            handle.run(1, SSBO_COUNTED=counted)
        with pytest.raises(ValueError, match=r"bound \['SSBO_READBACK'\] it does not declare, not bound \[\]"):
            handle.run(1, SSBO_COUNTED=counted, SSBO_SEGMENTS=segments, SSBO_READBACK=counted)
        handle.release()


def test_compile_error_names_the_included_file_and_line(glsl_copy):
    lib = glsl_copy / "lib" / "brdf.glsl"
    lines = lib.read_text().splitlines()
    target = next(i for i, line in enumerate(lines) if "float blinn_phong_exponent" in line) + 2  # a body line
    lines[target - 1] = "    this is not glsl;"
    lib.write_text("\n".join(lines) + "\n")
    with pytest.raises(engine.ShaderError) as error:
        engine.Renderer(16, 16, glsl_root=glsl_copy)
    assert str(error.value).startswith(f"glsl/lib/brdf.glsl:{target}:"), str(error.value)


def test_hot_reload_keeps_the_last_good_program_and_recovers(glsl_copy):
    """A broken edit leaves the old program running and reports file and line; fixing the file
    rebuilds the program and clears the error."""
    scene = engine.load_scene(GLSL_ROOT.parent / "scenes" / "cornell_box.json")
    with engine.Renderer(32, 32, glsl_root=glsl_copy) as r:
        before = r.render(scene, mode="direct")
        tonemap = glsl_copy / "lighting/shade_lights.frag"
        good = tonemap.read_text()
        broken = good.replace("out_radiance = vec4(radiance, 1.0);", "out_radiance = vec4(radiance, 1.0) oops;")
        tonemap.write_text(broken)
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 0 and len(errors) == 1
        line = broken.splitlines().index(next(l for l in broken.splitlines() if "oops" in l)) + 1
        assert str(errors[0]).startswith(f"glsl/lighting/shade_lights.frag:{line}:")
        assert (r.render(scene, mode="direct") == before).all(), "the last good program keeps rendering"
        tonemap.write_text(good.replace("out_radiance = vec4(radiance, 1.0);", "out_radiance = vec4(2.0 * radiance, 1.0);"))
        rebuilt, errors = r.reload_shaders()
        assert rebuilt >= 1 and errors == [] and r.programs.errors() == []
        after = r.render(scene, mode="direct")
        assert after.max() == pytest.approx(2.0 * before.max(), rel=1e-5)


def test_a_reloaded_voxel_shader_shows_on_the_next_frame_without_a_scene_change(glsl_copy):
    """With change tracking, nothing in the scene changed, yet an edit of the light injection
    (twice the direct light in the voxels) changes the indirect light of the next frame."""
    scene = engine.load_scene(GLSL_ROOT.parent / "scenes" / "cornell_box.json")
    with engine.Renderer(32, 32, glsl_root=glsl_copy) as r:
        r.track_changes = True
        before = r.render(scene, mode="indirect", grid=16, bounces=1)
        inject = glsl_copy / "inject/inject_direct_light.comp"
        text = inject.read_text()
        assert text.count("s.albedo / PI * irradiance") == 1
        inject.write_text(text.replace("s.albedo / PI * irradiance", "2.0 * s.albedo / PI * irradiance"))
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 1 and errors == []
        after = r.render(scene, mode="indirect", grid=16, bounces=1)
        assert after.mean() == pytest.approx(2.0 * before.mean(), rel=0.05)


def test_editing_an_included_library_rebuilds_its_users(glsl_copy):
    with engine.Renderer(16, 16, glsl_root=glsl_copy) as r:
        lib = glsl_copy / "lib" / "brdf.glsl"
        lib.write_text(lib.read_text() + "\n// touched\n")
        rebuilt, errors = r.reload_shaders()
        users = [h for h in r.programs.handles if any(f.endswith("brdf.glsl") for f in h.files)]
        assert errors == [] and rebuilt == len(users) >= 2


def _include_errors(errors, target):
    """The errors that say `#include "target": no such file` at a real file and line."""
    pattern = re.compile(rf'^glsl/[\w/.]+:\d+: error: #include "{re.escape(target)}": no such file$')
    return [str(error) for error in errors if pattern.match(str(error))]


def test_hot_reload_reports_a_deleted_library_at_each_include_and_recovers(glsl_copy):
    """Deleting an included file is an error at the line that includes it, in every program
    using it; the last good programs keep rendering; restoring the file clears the errors."""
    scene = engine.load_scene(GLSL_ROOT.parent / "scenes" / "cornell_box.json")
    with engine.Renderer(32, 32, glsl_root=glsl_copy) as r:
        before = r.render(scene, mode="direct")
        users = [h for h in r.programs.handles if any(f.endswith("brdf.glsl") for f in h.files)]
        brdf = glsl_copy / "lib" / "brdf.glsl"
        text = brdf.read_text()
        brdf.unlink()
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 0 and len(errors) == len(users) >= 2
        assert len(_include_errors(r.programs.errors(), "lib/brdf.glsl")) == len(users)
        line = 1 + (glsl_copy / "lighting/shade_lights.frag").read_text().splitlines().index('#include "lib/brdf.glsl"')
        assert f'glsl/lighting/shade_lights.frag:{line}: error: #include "lib/brdf.glsl": no such file' in map(str, errors)
        assert (r.render(scene, mode="direct") == before).all(), "the last good programs keep rendering"
        assert r.reload_shaders() == (0, []), "an unchanged missing file is not rebuilt again"
        brdf.write_text(text)
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == len(users) and errors == [] and r.programs.errors() == []


def test_hot_reload_reports_an_include_of_a_file_that_does_not_exist_until_it_is_created(glsl_copy):
    with engine.Renderer(16, 16, glsl_root=glsl_copy) as r:
        lighting = glsl_copy / "lighting/shade_lights.frag"
        lines = lighting.read_text().splitlines()
        lines.insert(2, '#include "lib/nowhere.glsl"')
        lighting.write_text("\n".join(lines) + "\n")
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 0
        assert [str(e) for e in errors] == ['glsl/lighting/shade_lights.frag:3: error: #include "lib/nowhere.glsl": no such file']
        assert [str(e) for e in r.programs.errors()] == [str(errors[0])]
        (glsl_copy / "lib" / "nowhere.glsl").write_text("// now it exists\n")
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 1 and errors == [] and r.programs.errors() == []


def test_hot_reload_reports_a_deleted_stage_file_and_recovers(glsl_copy):
    with engine.Renderer(16, 16, glsl_root=glsl_copy) as r:
        tonemap = glsl_copy / "tonemap/tone_map.frag"
        text = tonemap.read_text()
        tonemap.unlink()
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 0 and [str(e) for e in errors] == ["glsl/tonemap/tone_map.frag: error: no such file"]
        assert [str(e) for e in r.programs.errors()] == ["glsl/tonemap/tone_map.frag: error: no such file"]
        tonemap.write_text(text)
        rebuilt, errors = r.reload_shaders()
        assert rebuilt == 1 and errors == [] and r.programs.errors() == []
