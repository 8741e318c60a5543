"""vct: a small voxel cone tracing renderer (Python host, GLSL on OpenGL 4.5 via moderngl).

Its packages are layers, each importing only those before it: core, scene, formats, gpu, voxels,
passes, frame, app (tests/test_layers.py holds the order). This module is the Python API."""
from .core.errors import ContextError, SceneError, ShaderError, VctError, VctWarning
from .formats.output import save_exr, save_npy, save_png
from .formats.scene_api import check_scene, from_trimesh, triangle_mesh
from .formats.scene_file import framing_camera, load_scene
from .frame.renderer import Renderer
from .frame.settings import MODES, RenderSettings
from .scene.model import Camera, Environment, Light, Material, Mesh, Node, Scene, Texture, box_mesh, quad_mesh, sphere_mesh

__all__ = ["load_scene", "Renderer", "RenderSettings", "MODES", "save_png", "save_npy", "save_exr",
           "Scene", "Node", "Mesh", "Material", "Texture", "Light", "Camera", "Environment",
           "box_mesh", "quad_mesh", "sphere_mesh", "triangle_mesh", "framing_camera", "check_scene", "from_trimesh",
           "VctError", "VctWarning", "SceneError", "ShaderError", "ContextError"]
