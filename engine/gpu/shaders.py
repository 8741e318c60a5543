"""GLSL sources: a small `#include` preprocessor that keeps error lines mappable.

Every file gets a source-string number; `#line L N` directives are emitted around
each include, so a driver message such as "3:12(5): error: ..." can be translated
back to "glsl/lib/lights.glsl:12: error: ...".
"""
import ctypes
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core import constants
from ..core.errors import ShaderError
from ..core.limits import MAX_INCLUDE_DEPTH, MAX_SHADER_BYTES
from ..formats.input_files import os_problem, read_regular_file
from .bindings import bind_dispatch_indirect, bind_resources, use_program
from .functions import gl_functions

# An installed wheel carries the shaders as engine/glsl/; the source tree (and so an editable
# install, which reads it live) has them as the top-level glsl/.
_PACKAGE = Path(__file__).resolve().parent.parent  # engine/
GLSL_ROOT = _PACKAGE / "glsl" if (_PACKAGE / "glsl").is_dir() else _PACKAGE.parent / "glsl"
CONSTANTS_INCLUDE = "engine_constants.glsl"
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*$')
_VERSION = re.compile(r"^\s*#\s*version\b")
# Mesa: "3:12(5): error: ..."; NVIDIA: "3(12) : error ..."
_DRIVER_LINE = re.compile(r"^\s*(?:ERROR:\s*)?(\d+):(\d+)\((\d+)\):\s*(.*)$|^\s*(\d+)\((\d+)\)\s*:\s*(.*)$")


@dataclass
class Source:
    """A preprocessed stage: its text and the files it was made from (index = source number)."""

    text: str
    files: list = field(default_factory=list)

    def map_log(self, log):
        """Rewrite driver messages "N:L(C): msg" into "path:L: msg"."""
        out = []
        for line in log.splitlines():
            m = _DRIVER_LINE.match(line)
            if m and m.group(1) is not None:
                out.append(self._format(int(m.group(1)), int(m.group(2)), m.group(4)))
            elif m:
                out.append(self._format(int(m.group(5)), int(m.group(6)), m.group(7)))
            elif line.strip():
                out.append(line.strip())
        return out

    def _format(self, index, line, message):
        if line > FILE_LINE_STRIDE:  # the file index encoded in the line number wins
            index, line = divmod(line, FILE_LINE_STRIDE)
        return f"{self._name(index)}:{line}: {message}"

    def _name(self, index):
        return self.files[index] if 0 <= index < len(self.files) else f"<source {index}>"


FILE_LINE_STRIDE = 100000  # line numbers of file N start at N * FILE_LINE_STRIDE


def _line(index, number):
    """The `#line` number for line `number` of source file `index`: the index is encoded in
    the line too, since Mesa reports source string 0 for errors found after parsing."""
    return index * FILE_LINE_STRIDE + number


def _display(path, root):
    try:
        return str(Path("glsl") / Path(path).relative_to(root))
    except ValueError:
        return str(path)


def _read(path, where):
    """The text of a GLSL file (a regular file of at most MAX_SHADER_BYTES); a missing or
    unreadable one is a ShaderError worded like a compiler message, `where` first
    (`glsl/a.frag:4: error: #include "lib/b.glsl"`)."""
    try:
        return read_regular_file(path, MAX_SHADER_BYTES).decode("utf-8")
    except FileNotFoundError:
        raise ShaderError(f"{where}: no such file") from None
    except UnicodeDecodeError as exc:
        raise ShaderError(f"{where}: cannot read (not UTF-8 text: byte {exc.start})") from None
    except (OSError, ValueError) as exc:
        raise ShaderError(f"{where}: cannot read ({os_problem(exc)})") from None


def preprocess(name, defines=None, root=GLSL_ROOT, read_paths=None):
    """Read glsl/<name>, expand includes (relative to glsl/), inject `defines` after #version.
    `read_paths`, a set, collects every file looked for, found or not (to watch for changes)."""
    root = Path(root)
    files = []
    seen = set()
    read_paths = set() if read_paths is None else read_paths

    def expand(path, text, stack):
        index = len(files)
        files.append(_display(path, root) if path != CONSTANTS_INCLUDE else "engine/core/constants.py")
        out = [] if index == 0 else [f"#line {_line(index, 1)} {index}"]
        for number, line in enumerate(text.splitlines(), start=1):
            m = _INCLUDE.match(line)
            if m:
                target = m.group(1)
                if target in stack:
                    raise ShaderError(f"{files[index]}:{number}: error: include cycle through {target}")
                if len(stack) >= MAX_INCLUDE_DEPTH:
                    raise ShaderError(f"{files[index]}:{number}: error: #include nests more than {MAX_INCLUDE_DEPTH} files deep")
                if target in seen:
                    out.append(f"// {target} already included")
                    continue
                seen.add(target)
                if target == CONSTANTS_INCLUDE:
                    sub_text = constants.glsl_header()
                    sub_path = CONSTANTS_INCLUDE
                else:
                    sub_path = root / target
                    read_paths.add(sub_path)
                    sub_text = _read(sub_path, f'{files[index]}:{number}: error: #include "{target}"')
                out.extend(expand(sub_path, sub_text, stack | {target}))
                out.append(f"#line {_line(index, number + 1)} {index}")
            elif index == 0 and _VERSION.match(line):
                out.append(line)
                for key, value in (defines or {}).items():
                    out.append(f"#define {key} {value}")
                out.append(f"#line {number + 1} 0")
            else:
                out.append(line)
        return out

    path = root / name
    read_paths.add(path)
    lines = expand(path, _read(path, f"{_display(path, root)}: error"), frozenset())
    return Source("\n".join(lines) + "\n", files)


_BINDING = re.compile(r"layout\s*\([^)]*\bbinding\s*=\s*(IMG|TEX|SSBO|UBO)_(\w+)")
_LINE_DIRECTIVE = re.compile(r"^#line (\d+) (\d+)$")
BINDING_UNITS = {"IMG": constants.IMAGE_UNIT, "TEX": constants.TEXTURE_UNIT, "SSBO": constants.STORAGE_BINDING,
                 "UBO": constants.UNIFORM_BLOCK}


def check_bindings(sources):
    """Refuse a program whose stages declare two resources of one kind (image units IMG_*,
    samplers TEX_*, storage blocks SSBO_*, uniform blocks UBO_*) at one binding number: the
    host binds by name, and two names on one unit would read each other's data."""
    declared = {}  # (kind, number) -> (name, where)
    for source in sources.values():
        index, number = 0, 1
        for line in source.text.splitlines():
            directive = _LINE_DIRECTIVE.match(line)
            if directive:
                number, index = int(directive.group(1)), int(directive.group(2))
                continue
            for kind, name in _BINDING.findall(line):
                if name in BINDING_UNITS[kind]:
                    where = source._format(index, number, "").rstrip(": ")
                    other, other_where = declared.setdefault((kind, BINDING_UNITS[kind][name]), (name, where))
                    if other != name:
                        raise ShaderError(f"{where}: error: {kind}_{name} is bound at {BINDING_UNITS[kind][name]}, as "
                                          f"{kind}_{other} is ({other_where}): one program cannot bind both")
            number += 1


_DECLARATION = re.compile(r"layout\s*\(([^)]*)\)\s*((?:(?:uniform|buffer|readonly|writeonly|restrict|coherent|volatile)\s+)+)"
                          r"(\w+)\s*(\w*)")


def declared_resources(sources):
    """The resources the stages declare at the bindings of constants.py: {GLSL name (a sampler,
    an image or a block): (binding name "KIND_NAME", "read" | "write" | "read write")}.
    Samplers and uniform blocks are read; images and storage blocks as qualified."""
    declared = {}
    for source in sources.values():
        for layout, qualifiers, first, second in _DECLARATION.findall(source.text):
            binding = _BINDING.search(f"layout({layout})")
            if binding is None:
                continue
            kind = binding.group(1)
            words = qualifiers.split()
            block = "buffer" in words or kind == "UBO"
            access = "read" if kind in ("TEX", "UBO") or "readonly" in words else "write" if "writeonly" in words else "read write"
            declared[first if block else second] = (f"{kind}_{binding.group(2)}", access)
    return declared


def check_declared(program, sources, reads, writes):
    """Refuse a program that uses a resource its pass does not declare (`reads`, `writes`:
    binding names "KIND_NAME"), declares one its sources do not, or declares a read-only
    resource (a sampler, a uniform block, a readonly image or block) in `writes` or a
    writeonly one in `reads`: the pass's declaration is what the program may bind, and how."""
    declared = declared_resources(sources)
    files = ", ".join(source.files[0] for source in sources.values())
    access_of = {binding: access for binding, access in declared.values()}
    for binding in sorted(set(reads) | set(writes)):
        access = access_of.get(binding)
        if access is None:
            raise ShaderError(f"{files}: error: its pass declares {binding}, which no stage declares")
        if (access == "read" and binding in writes) or (access == "write" and binding in reads):
            listed = "writes" if binding in writes else "reads"
            raise ShaderError(f"{files}: error: its pass declares {binding} in {listed}, which the shader declares {access}-only")
    for name in program:
        entry = declared.get(re.sub(r"\[\d+\]$", "", name))
        if entry is not None and entry[0] not in reads and entry[0] not in writes:
            raise ShaderError(f"{files}: error: uses {entry[0]}, which its pass does not declare")


def compile_sources(ctx, sources):
    """Compile and link preprocessed stages ({'vertex_shader': Source, ...}, or just
    'compute_shader'), after check_bindings. Errors raise ShaderError naming the real file and
    line."""
    check_bindings(sources)
    try:
        if "compute_shader" in sources:
            return ctx.compute_shader(sources["compute_shader"].text)
        return ctx.program(**{stage: src.text for stage, src in sources.items()})
    except Exception as exc:  # moderngl raises a plain Error with the driver log
        raise _shader_error(exc, sources) from None


def _shader_error(exc, sources):
    """ShaderError from a moderngl failure; the log is split by stage ("fragment_shader\n===")
    and each stage's lines are mapped through that stage's source files."""
    text = str(exc)
    blocks = re.split(r"^(vertex_shader|geometry_shader|fragment_shader|compute_shader)\n=+\n", text, flags=re.M)
    lines = []
    if len(blocks) > 1:
        for stage, log in zip(blocks[1::2], blocks[2::2]):
            source = sources.get(stage)
            if source is not None:
                lines += [line for line in source.map_log(log) if re.match(r"^\S+:\d+: ", line)]
    elif len(sources) == 1:
        source = next(iter(sources.values()))
        lines = [line for line in source.map_log(text) if re.match(r"^\S+:\d+: ", line)]
    if not lines:
        names = ", ".join(src.files[0] for src in sources.values())
        lines = [f"{names}: " + " ".join(l.strip() for l in text.splitlines() if l.strip() and set(l.strip()) != {"="})]
    error = ShaderError(lines[0])
    error.lines = lines
    return error


UNIFORM_KINDS = {"f": ("<f4", "f"), "i": ("<i4", "i"), "I": ("<u4", "ui")}  # moderngl's fmt -> numpy, GL suffix


def _write_uniform(program, member, value):
    """Write a uniform of `program` (moderngl's Uniform `member`) with glProgramUniform*: `value`
    bytes (its leading elements, as many as the uniform has), or numbers."""
    kind = member.fmt[-1]
    dtype, suffix = UNIFORM_KINDS[kind]
    data = bytes(value) if isinstance(value, (bytes, bytearray)) else np.asarray(value, dtype).tobytes()
    data = data[:member.array_length * member.element_size]
    count = max(1, len(data) // member.element_size)
    buffer = ctypes.create_string_buffer(data, len(data))
    gl = gl_functions(program.ctx)
    if member.matrix:
        side = 3 if member.dimension == 9 else 4
        getattr(gl, f"glProgramUniformMatrix{side}fv")(program.glo, member.location, count, 0, buffer)
    else:
        getattr(gl, f"glProgramUniform{member.dimension}{suffix}v")(program.glo, member.location, count, buffer)


def _same_value(a, b):
    """Whether two uniform values (numbers, bools, bytes, tuples of them) are the same value."""
    try:
        return type(a) is type(b) and bool(a == b)
    except ValueError:  # arrays inside: compared element by element
        return False


def _mtime(path):
    """Modification time in ns, None for a file that is missing."""
    try:
        return path.stat().st_mtime_ns
    except OSError:
        return None


class ProgramHandle:
    """A program that can be rebuilt when its files change. `program` always holds the last
    good build; `error` holds the last failure (None once a rebuild succeeds)."""

    def __init__(self, library, stages, defines, reads, writes):
        self.library = library
        self.reads, self.writes = tuple(reads), tuple(writes)  # binding names "KIND_NAME" (check_declared)
        self.declared = frozenset(self.reads) | frozenset(self.writes)  # what each dispatch or draw binds (bind)
        self.stages = stages  # {'vertex_shader': 'gbuffer/draw_surfaces.vert', ...} or {'compute_shader': ...}
        self.defines = dict(defines or {})
        self.program = None
        self.error = None
        self.files = ()
        self._mtimes = {}
        self.build()

    def build(self):
        """Preprocess and compile; on success replace the program, on failure (a missing or
        broken file, a compile error) keep the old one, record the error and raise it. Either
        way the files read or looked for are watched for the next change."""
        ctx, root = self.library.ctx, self.library.root
        paths = set()
        try:
            sources = {stage: preprocess(name, self.defines, root, paths) for stage, name in self.stages.items()}
            program = compile_sources(ctx, sources)
            try:
                check_declared(program, sources, self.reads, self.writes)
            except ShaderError:
                program.release()
                raise
        except ShaderError as exc:
            self.error = exc
            raise
        finally:
            self._mtimes = {p: _mtime(p) for p in paths}
        if self.program is not None:
            self.program.release()
        self.program, self.error, self.files = program, None, tuple(sorted(map(str, paths)))
        self._uniforms = {}  # name -> the value the program's uniform holds (`set`)
        return program

    def changed(self):
        return any(_mtime(p) != t for p, t in self._mtimes.items())

    def release(self):
        if self.program is not None:
            self.program.release()
            self.program = None
        self.library.handles.discard(self)

    def __getitem__(self, name):
        return self.program[name]

    def set(self, **uniforms):
        """Set the uniforms the program uses; ones the compiler removed are skipped, and so are
        the trailing elements of an array it shortened to the ones it reads. A uniform that
        holds the value given already is not written again: most of a frame's uniforms hold what
        they held the frame before. A write is one GL call (glProgramUniform*: the program is
        not bound for it)."""
        held = self._uniforms
        for name, value in uniforms.items():
            if name in held and _same_value(held[name], value):
                continue
            if name in self.program:
                _write_uniform(self.program, self.program[name], value)
            held[name] = value

    def bind(self, resources):
        """Bind what a dispatch or draw of the program reads and writes, by binding name
        ({"SSBO_VOXEL_BASE": buffer, ...}: gpu.bindings.bind_resources): exactly the resources
        its pass declares, so nothing it reads is left as another pass bound it and nothing is
        bound that it does not declare."""
        given, declared = resources.keys(), self.declared
        if given != declared:
            raise ValueError(f"{', '.join(self.stages.values())}: bound {sorted(given - declared)} it does not declare, "
                             f"not bound {sorted(declared - given)}")
        bind_resources(resources)

    def run(self, x=1, y=1, z=1, **resources):
        """Dispatch the compute program over x * y * z workgroups, its `resources` bound (bind)."""
        self.bind(resources)
        use_program(self.program)
        gl_functions(self.program.ctx).glDispatchCompute(x, y, z)

    def run_indirect(self, buffer, offset=0, **resources):
        """Dispatch the compute program over the workgroup counts at byte `offset` of `buffer`,
        its `resources` bound (bind)."""
        self.bind(resources)
        use_program(self.program)
        bind_dispatch_indirect(buffer)
        gl_functions(self.program.ctx).glDispatchComputeIndirect(offset)


class ProgramLibrary:
    """Builds every program of a renderer and rebuilds the ones whose files changed."""

    def __init__(self, ctx, root=GLSL_ROOT):
        self.ctx = ctx
        self.root = Path(root)
        self.handles = set()

    def program(self, defines=None, reads=(), writes=(), **stages):
        """A program of `stages` ({stage: file}), which binds what `reads` and `writes` name
        (binding names of constants.py, "TEX_VOXEL_ALBEDO"; check_declared) and nothing else."""
        handle = ProgramHandle(self, stages, defines, reads, writes)
        self.handles.add(handle)
        return handle

    def compute(self, name, defines=None, reads=(), writes=()):
        return self.program(defines, reads, writes, compute_shader=name)

    def reload_changed(self):
        """Rebuild programs whose sources changed. Returns (rebuilt count, [ShaderError])."""
        rebuilt, errors = 0, []
        for handle in list(self.handles):
            if handle.changed():
                try:
                    handle.build()
                    rebuilt += 1
                except ShaderError as exc:
                    errors.append(exc)
        return rebuilt, errors

    def errors(self):
        return [h.error for h in self.handles if h.error is not None]

    def files(self):
        """The GLSL files the programs were built from."""
        return sorted({path for handle in self.handles for path in handle.files})
