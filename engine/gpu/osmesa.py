"""Headless OpenGL core contexts through Mesa's OSMesa (libosmesa6), for hosts where EGL is missing.

glcontext has no OSMesa backend, so libOSMesa is driven with ctypes and its context is handed to
moderngl as a loader object (load_opengl_function / release / __enter__ / __exit__). The context
renders into a 1x1 buffer that is never read: all drawing goes to framebuffer objects.
"""
import ctypes
import ctypes.util
from collections import deque

import moderngl

from ..core.errors import ContextError

# Attribute names and values from Mesa's GL/osmesa.h.
OSMESA_FORMAT = 0x22
OSMESA_RGBA = 0x1908  # GL_RGBA
OSMESA_DEPTH_BITS = 0x30
OSMESA_PROFILE = 0x33
OSMESA_CORE_PROFILE = 0x34
OSMESA_CONTEXT_MAJOR_VERSION = 0x36
OSMESA_CONTEXT_MINOR_VERSION = 0x37
GL_UNSIGNED_BYTE = 0x1401

LIBRARY_NAMES = (ctypes.util.find_library("OSMesa"), "libOSMesa.so.8", "libOSMesa.so.6")


def load_osmesa_library():
    """libOSMesa with the prototypes used here declared, or ContextError when it is not installed."""
    for name in filter(None, LIBRARY_NAMES):
        try:
            library = ctypes.CDLL(name)
            break
        except OSError:
            continue
    else:
        raise ContextError("libOSMesa not found (Debian: apt-get install libosmesa6)")
    if not hasattr(library, "OSMesaCreateContextAttribs"):
        raise ContextError("libOSMesa is too old: it lacks OSMesaCreateContextAttribs (core profiles)")
    library.OSMesaCreateContextAttribs.restype = ctypes.c_void_p
    library.OSMesaCreateContextAttribs.argtypes = [ctypes.POINTER(ctypes.c_int), ctypes.c_void_p]
    library.OSMesaMakeCurrent.restype = ctypes.c_ubyte
    library.OSMesaMakeCurrent.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_int]
    library.OSMesaGetProcAddress.restype = ctypes.c_void_p
    library.OSMesaGetProcAddress.argtypes = [ctypes.c_char_p]
    library.OSMesaDestroyContext.restype = None
    library.OSMesaDestroyContext.argtypes = [ctypes.c_void_p]
    return library


class OSMesaContext:
    """One OSMesa core-profile context, shaped as the loader moderngl expects of a glcontext backend."""

    def __init__(self, library, major, minor):
        self.library = library
        attributes = [OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                      OSMESA_CONTEXT_MAJOR_VERSION, major, OSMESA_CONTEXT_MINOR_VERSION, minor, 0]
        self.handle = library.OSMesaCreateContextAttribs((ctypes.c_int * len(attributes))(*attributes), None)
        if not self.handle:
            raise ContextError(f"OSMesa could not create an OpenGL {major}.{minor} core context")
        self.color_buffer = ctypes.create_string_buffer(4)  # 1x1 RGBA8; must outlive the context
        try:
            self.__enter__()
        except ContextError:
            self.release()
            raise

    def __enter__(self):
        if not self.library.OSMesaMakeCurrent(self.handle, self.color_buffer, GL_UNSIGNED_BYTE, 1, 1):
            raise ContextError("OSMesaMakeCurrent failed")
        return self

    def __exit__(self, *exc_info):
        pass  # the context simply stays current

    def load_opengl_function(self, name):
        return self.library.OSMesaGetProcAddress(name.encode()) or 0

    def release(self):
        if self.handle:
            self.library.OSMesaDestroyContext(self.handle)
            self.handle = None


def create_osmesa_context(required_version):
    """A standalone moderngl.Context on OSMesa of at least required_version (e.g. 450 for OpenGL 4.5)."""
    major, minor = required_version // 100, required_version // 10 % 10
    osmesa_context = OSMesaContext(load_osmesa_library(), major, minor)
    try:
        # What moderngl.create_standalone_context does, with our loader in place of a glcontext backend.
        ctx = moderngl.Context.__new__(moderngl.Context)
        ctx.mglo, ctx.version_code = moderngl.mgl.create_context(context=osmesa_context)
    except Exception as exc:
        osmesa_context.release()
        raise ContextError(f"moderngl could not use the OSMesa context: {exc}") from exc
    ctx._info, ctx._extensions, ctx.extra, ctx._gc_mode, ctx._objects = None, None, None, None, deque()
    ctx._screen, ctx.fbo = None, None
    ctx.osmesa_context = osmesa_context  # kept alive with ctx; ctx.release() destroys it via the loader
    if ctx.version_code < required_version:
        ctx.release()
        raise ContextError(f"OSMesa gave OpenGL {ctx.version_code // 100}.{ctx.version_code // 10 % 10}, "
                           f"need {major}.{minor}")
    return ctx
