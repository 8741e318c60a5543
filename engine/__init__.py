"""vct: a small voxel cone tracing renderer (Python host, GLSL on OpenGL 4.5 via moderngl)."""
from .errors import ContextError, SceneError, ShaderError, VctError, VctWarning
from .output import save_exr, save_npy, save_png
from .renderer import Renderer
from .scene_file import load_scene
from .settings import MODES, RenderSettings

__all__ = ["load_scene", "Renderer", "RenderSettings", "MODES", "save_png", "save_npy", "save_exr",
           "VctError", "VctWarning", "SceneError", "ShaderError", "ContextError"]
