"""OpenGL 4.5 core contexts: headless EGL by default, OSMesa where EGL is missing."""
import os

import moderngl

from ..core.errors import ContextError

REQUIRED_VERSION = 450


def create_headless_context():
    """A standalone OpenGL 4.5 context: EGL first (on the EGL device VCT_EGL_DEVICE names, 0 by
    default: a batch worker's GPU), then OSMesa. One clear error if neither works."""
    reasons = []
    backends = [os.environ["VCT_GL_BACKEND"]] if os.environ.get("VCT_GL_BACKEND") else ["egl", "osmesa"]
    for backend in backends:
        try:
            if backend == "egl":
                device = os.environ.get("VCT_EGL_DEVICE", "0")
                if not device.isdigit():
                    raise ContextError(f"VCT_EGL_DEVICE must be a device's index, got {device!r}")
                return moderngl.create_standalone_context(backend="egl", require=REQUIRED_VERSION, device_index=int(device))
            if backend == "osmesa":
                from .osmesa import create_osmesa_context

                return create_osmesa_context(REQUIRED_VERSION)
            reasons.append(f"{backend}: unknown backend (use egl or osmesa)")
        except ContextError as exc:
            reasons.append(f"{backend}: {exc}")
        except Exception as exc:  # moderngl/glcontext raise plain exceptions for missing libraries
            reasons.append(f"{backend}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")
    raise ContextError("no OpenGL 4.5 context (" + "; ".join(reasons) + "); install Mesa's EGL/GL libraries "
                       "(Debian: libegl1 libegl-mesa0 libgl1-mesa-dri)")


def renderer_name(ctx):
    return f"{ctx.info['GL_RENDERER']} / OpenGL {ctx.info['GL_VERSION']}"
