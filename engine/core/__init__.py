"""What every layer shares and nothing GPU-specific: user-facing errors and warnings, the limits
of every input, the constants host and shaders share (generated into GLSL), transforms, the
specular lobe's table, progress bars."""
