"""Binding by name, through a record of what each context has bound: a pass that binds a
resource where it is bound already issues no GL call. The passes of a frame share most of what
they read (the voxels' records, the G-buffer, the lights), so without the record each would bind
it again; a frame's GL calls then grow with its passes instead of with what changes.

Every texture unit, image unit and buffer binding point the engine uses is bound here, and so
are the program and indirect buffer of a compute dispatch; moderngl itself binds only its
scratch unit (ctx.default_texture_unit) and non-indexed buffer targets, and the program of a
draw (`program_used` notes it).
GL code outside the engine (the viewer's GUI, a caller's own drawing) may bind what it likes in
between: the renderer forgets the record (`forget_bindings`) when a frame starts.

A record holds the objects it saw bound, so an object is never mistaken for a new one made in
its place; a buffer deleted while bound unbinds, and a new one at its name is a new object.

A dispatch or a draw binds its resources by binding name in one mapping (`bind_resources`,
through ProgramHandle.bind, which checks it against what the program declares)."""
import weakref
from dataclasses import dataclass

from ..core.constants import IMAGE_UNIT, STORAGE_BINDING, TEXTURE_UNIT, UNIFORM_BLOCK
from .functions import GL_DISPATCH_INDIRECT_BUFFER, gl_functions

_RECORDS = weakref.WeakKeyDictionary()  # context -> {binding point: what is bound there}


def _record(ctx):
    record = _RECORDS.get(ctx)
    if record is None:
        record = _RECORDS[ctx] = {}
    return record


def _bound(ctx, point, state):
    """Whether `state` (a tuple of objects and settings) is bound at `point` already; records it
    as bound if not (the caller binds it)."""
    record = _record(ctx)
    held = record.get(point)
    if held is not None and len(held) == len(state) and all(a is b or a == b for a, b in zip(held, state)):
        return True
    record[point] = state
    return False


def forget_bindings(ctx):
    """Forget what the context has bound: the next bind of each point binds."""
    _record(ctx).clear()


def bind_storage(buffer, name):
    """`buffer` at the storage binding STORAGE_BINDING[name]."""
    binding = STORAGE_BINDING[name]
    if not _bound(buffer.ctx, ("ssbo", binding), (buffer,)):
        buffer.bind_to_storage_buffer(binding)


def bind_uniform_block(buffer, name):
    """`buffer` at the uniform block binding UNIFORM_BLOCK[name]."""
    binding = UNIFORM_BLOCK[name]
    if not _bound(buffer.ctx, ("ubo", binding), (buffer,)):
        buffer.bind_to_uniform_block(binding)


def bind_texture(texture, name):
    """`texture` at the texture unit TEXTURE_UNIT[name] (or a unit number)."""
    unit = TEXTURE_UNIT[name] if isinstance(name, str) else name
    if not _bound(texture.ctx, ("texture", unit), (texture,)):
        texture.use(unit)


def bind_image(texture, name, read=False, write=True, level=0, format=0):
    """A level of `texture` at the image unit IMAGE_UNIT[name], with its access and format."""
    unit = IMAGE_UNIT[name]
    if not _bound(texture.ctx, ("image", unit), (texture, read, write, level, format)):
        texture.bind_to_image(unit, read=read, write=write, level=level, format=format)


def use_program(program):
    """Make a moderngl program (or compute shader) the current one."""
    if not _bound(program.ctx, ("program",), (program,)):
        gl_functions(program.ctx).glUseProgram(program.glo)


def program_used(program):
    """Note that moderngl made `program` the current one (it binds a draw's own)."""
    _record(program.ctx)[("program",)] = (program,)


def bind_dispatch_indirect(buffer):
    """`buffer` as the buffer indirect dispatches read their sizes from."""
    if not _bound(buffer.ctx, ("dispatch indirect",), (buffer,)):
        gl_functions(buffer.ctx).glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, buffer.glo)


@dataclass(frozen=True)
class Image:
    """A level of a texture as an image unit binds it: with its access and format."""
    texture: object
    level: int = 0
    read: bool = False
    write: bool = True
    format: int = 0


def bind_resources(resources):
    """Bind each resource at the binding its name gives: "SSBO_X" or "UBO_X" a buffer, "TEX_X" a
    texture (or a sequence of them, at consecutive units from X's), "IMG_X" an Image. None
    binds nothing: a resource the program does not read this time."""
    for binding, resource in resources.items():
        if resource is None:
            continue
        kind, name = binding.split("_", 1)
        if kind == "SSBO":
            bind_storage(resource, name)
        elif kind == "UBO":
            bind_uniform_block(resource, name)
        elif kind == "TEX":
            if isinstance(resource, (list, tuple)):
                for index, texture in enumerate(resource):
                    bind_texture(texture, TEXTURE_UNIT[name] + index)
            else:
                bind_texture(resource, name)
        else:
            bind_image(resource.texture, name, read=resource.read, write=resource.write, level=resource.level,
                       format=resource.format)
