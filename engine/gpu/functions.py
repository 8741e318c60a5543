"""The few OpenGL 4.5 entry points moderngl does not wrap, called through ctypes: texture arrays
of a given internal format (sRGB arrays: moderngl's texture_array has no internal format) and
their parameters, bound with one call a unit; the viewports of a viewport array; buffer writes
without a bind (glNamedBufferSubData); a region of a depth texture cleared in one call
(glClearTexSubImage); blending set per draw buffer (glBlendFunci); uniforms
written to a program without binding it (glProgramUniform*), and compute dispatches that bind
the program and the indirect buffer only where they are not bound already (engine/gpu/shaders.py).

The functions come from the context's own loader: OSMesa's for an OSMesa context
(engine/gpu/osmesa.py), else libGL, whose entry points dispatch to the current EGL or GLX context
(glvnd)."""
import ctypes
import ctypes.util
import functools
import weakref

GL_TEXTURE_2D_ARRAY = 0x8C1A
GL_TEXTURE_MIN_FILTER = 0x2801
GL_TEXTURE_MAG_FILTER = 0x2800
GL_TEXTURE_WRAP_S = 0x2802
GL_TEXTURE_WRAP_T = 0x2803
GL_LINEAR = 0x2601
GL_LINEAR_MIPMAP_LINEAR = 0x2703
GL_REPEAT = 0x2901
GL_CLAMP_TO_EDGE = 0x812F
GL_MIRRORED_REPEAT = 0x8370
GL_RGBA = 0x1908
GL_UNSIGNED_BYTE = 0x1401
GL_SRGB8_ALPHA8 = 0x8C43
GL_RGBA8 = 0x8058
GL_UNPACK_ALIGNMENT = 0x0CF5
WRAP_MODES = {"REPEAT": GL_REPEAT, "CLAMP_TO_EDGE": GL_CLAMP_TO_EDGE, "MIRRORED_REPEAT": GL_MIRRORED_REPEAT}

_u, _i, _p = ctypes.c_uint, ctypes.c_int, ctypes.c_void_p
PROTOTYPES = {
    "glCreateTextures": (None, _u, _i, ctypes.POINTER(_u)),
    "glDeleteTextures": (None, _i, ctypes.POINTER(_u)),
    "glTextureStorage3D": (None, _u, _i, _u, _i, _i, _i),
    "glTextureSubImage3D": (None, _u, _i, _i, _i, _i, _i, _i, _i, _u, _u, _p),
    "glGenerateTextureMipmap": (None, _u),
    "glTextureParameteri": (None, _u, _u, _i),
    "glBindTextureUnit": (None, _u, _u),
    "glPixelStorei": (None, _u, _i),
    "glViewportArrayv": (None, _u, _i, ctypes.POINTER(ctypes.c_float)),
    "glScissorArrayv": (None, _u, _i, ctypes.POINTER(ctypes.c_int)),
    "glUseProgram": (None, _u),
    "glNamedBufferSubData": (None, _u, ctypes.c_ssize_t, ctypes.c_ssize_t, _p),
    "glClearTexSubImage": (None, _u, _i, _i, _i, _i, _i, _i, _i, _u, _u, _p),
    "glPushDebugGroup": (None, _u, _u, _i, ctypes.c_char_p),
    "glBlendFunci": (None, _u, _u, _u),
    "glPopDebugGroup": (None,),
    "glBindBuffer": (None, _u, _u),
    "glDispatchCompute": (None, _u, _u, _u),
    "glDispatchComputeIndirect": (None, ctypes.c_ssize_t),
    **{f"glProgramUniform{n}{kind}v": (None, _u, _i, _i, _p) for n in (1, 2, 3, 4) for kind in ("f", "i", "ui")},
    **{f"glProgramUniformMatrix{n}fv": (None, _u, _i, _i, ctypes.c_ubyte, _p) for n in (3, 4)},
}
GL_DISPATCH_INDIRECT_BUFFER = 0x90EE
GL_DEPTH_COMPONENT = 0x1902
GL_FLOAT = 0x1406
GL_DEBUG_SOURCE_APPLICATION = 0x824A


@functools.lru_cache(maxsize=None)
def _libgl():
    return ctypes.CDLL(ctypes.util.find_library("GL") or "libGL.so.1")


class GLFunctions:
    """The entry points of PROTOTYPES for one context, by name (`gl.glBindTextureUnit(...)`)."""

    def __init__(self, ctx):
        loader = getattr(ctx, "osmesa_context", None)
        for name, (restype, *argtypes) in PROTOTYPES.items():
            if loader is not None:
                function = ctypes.CFUNCTYPE(restype, *argtypes)(loader.load_opengl_function(name))
            else:
                function = getattr(_libgl(), name)
                function.restype, function.argtypes = restype, argtypes
            setattr(self, name, function)


def write_buffer(buffer, data, offset=0):
    """Write bytes into a moderngl Buffer at `offset` with one call (glNamedBufferSubData: it is
    not bound for it)."""
    data = bytes(data)
    gl_functions(buffer.ctx).glNamedBufferSubData(buffer.glo, offset, len(data), data)


def clear_depth(texture, rect, depth=1.0):
    """Set a rectangle (x, y, width, height) of a depth texture's level 0 to `depth` with one
    call, without a framebuffer (glClearTexSubImage)."""
    value = ctypes.c_float(depth)
    gl_functions(texture.ctx).glClearTexSubImage(texture.glo, 0, *rect[:2], 0, *rect[2:], 1, GL_DEPTH_COMPONENT, GL_FLOAT,
                                                 ctypes.byref(value))


_FUNCTIONS = weakref.WeakKeyDictionary()


def gl_functions(ctx):
    """The GLFunctions of a context (made once)."""
    functions = _FUNCTIONS.get(ctx)
    if functions is None:
        functions = _FUNCTIONS[ctx] = GLFunctions(ctx)
    return functions
