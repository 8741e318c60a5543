"""A frame: render settings, the frame's camera, the radiance schedule (GL-free: which voxels get
light, bounces and mipmaps when) and the Renderer, which wires the passes in plain order."""
