"""vct: a small voxel cone tracing renderer (Python host, GLSL on OpenGL 4.5 via moderngl)."""
from .errors import ContextError, SceneError, ShaderError, VctError, VctWarning
from .output import save_exr, save_npy, save_png
from .renderer import Renderer
from .scene import Camera, Environment, Light, Material, Mesh, Node, Scene, Texture, box_mesh, quad_mesh, sphere_mesh
from .scene_api import check_scene, from_trimesh, triangle_mesh
from .scene_file import framing_camera, load_scene
from .settings import MODES, RenderSettings

__all__ = ["load_scene", "Renderer", "RenderSettings", "MODES", "save_png", "save_npy", "save_exr",
           "Scene", "Node", "Mesh", "Material", "Texture", "Light", "Camera", "Environment",
           "box_mesh", "quad_mesh", "sphere_mesh", "triangle_mesh", "framing_camera", "check_scene", "from_trimesh",
           "VctError", "VctWarning", "SceneError", "ShaderError", "ContextError"]
