"""GPU plumbing: the OpenGL 4.5 context (EGL, OSMesa), the shader preprocessor and program
library, bindings by name, the GL calls moderngl lacks, timer queries, and the scene resident on
the GPU (shared mesh buffers, draw and material records, texture arrays, emitters, the sky)."""
