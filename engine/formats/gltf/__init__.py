"""glTF 2.0 files -> scene-graph nodes with meshes, materials, textures, cameras, lights and
animations (plain Python/numpy, no GL); engine/formats/mesh_files.py's load_mesh_file reads them here:
container.py (document, buffers, accessors), nodes.py (hierarchy and animations), meshes.py,
materials.py (with their textures), cameras_lights.py.

From a .gltf file (with its buffers and images) or a .glb: the default scene's node hierarchy
(names; translation/rotation/scale or a matrix), one child node per primitive where a mesh has
several, each with its material (the mapping is in engine.scene.model.Material's docstring). NORMAL,
TEXCOORD_0, TEXCOORD_1, TANGENT and COLOR_0 come from the file; a primitive without NORMAL
gets flat normals (as the glTF spec says), one whose material has a normal texture but no
TANGENT gets tangents from its texture coordinates (Lengyel's per-triangle derivatives,
summed per vertex). Triangle lists, strips and fans; sparse accessors; data URIs and
external files. Cameras become NodeCameras of their nodes (perspective yfov and aspectRatio,
orthographic xmag/ymag; the node's -z is the view direction, +y up); KHR_lights_punctual
lights become Lights of their nodes (at the node's origin, shining along its -z): colour x
intensity, point and spot in candela, directional in lux, over LUMENS_PER_WATT = 683 into
W/sr and W/m^2; range; a spot's innerConeAngle and outerConeAngle (radians) as its inner and
outer angles. Skins: JOINTS_n and WEIGHTS_n (every set, weights scaled to sum to 1) on the
mesh, the node's skin a Skin (its joints the scene's nodes, inverseBindMatrices, identity
where absent); morph targets: POSITION, NORMAL and TANGENT displacements, the mesh's weights
its target_weights, a node's weights its morph_weights (on every node drawing one of its
primitives). Animations: each channel that moves a node's translation, rotation, scale or
weights (LINEAR, STEP, CUBICSPLINE) becomes a Sampler of the node's NodeTracks
(engine.scene.animation), under the animation's name ("animation N" where it has none).
Extensions the file uses without
requiring them and vct does not read are left out, as glTF allows, with one warning naming
them; so are their animation targets (KHR_animation_pointer's), a texture whose image only an
extension gives (one warning each) and, as the spec says, primitives without POSITION (one
warning for the file). JSON numbers written with a zero fraction (1.0) read as integers.

Images are decoded once per file: materials that use the same image (by content) the same way
share one Texture object. Primitives without a material get a grey Lambertian default (albedo
0.8, like a scene material with no fields). The file, its buffers and its images are read
through the scene's InputFiles (engine/formats/input_files.py), and what the file holds is held to
engine/core/limits.py: vertex data finite and within +-1e6, materials within their ranges, nodes
nested at most MAX_DEPTH levels. Bad input raises SceneError naming the file and the element,
e.g. `sponza.glb: materials[3].pbrMetallicRoughness.baseColorTexture: images[5] "bricks.png":
file not found`.
"""
from ...core.errors import warn
from ..mesh_building import FileTextures, default_material
from .cameras_lights import CameraLightReader
from .container import GltfContainer
from .materials import MaterialReader
from .meshes import MeshReader
from .nodes import NodeReader

# The extensions this reader understands; others a file uses are left out, with a warning.
GLTF_EXTENSIONS = ("KHR_materials_emissive_strength", "KHR_lights_punctual", "KHR_texture_transform")


class GltfFile(GltfContainer, NodeReader, MeshReader, MaterialReader, CameraLightReader):
    """One glTF file: its document, buffers, and what was built from it (meshes, materials and
    textures, each once)."""

    def __init__(self, path, data, name, material, inputs):
        super().__init__(path, data, name, inputs)
        self.override = material
        self.meshes = {}
        self.materials = {}
        self.default = default_material()
        self.textures = FileTextures(inputs)
        self.placed = set()  # the nodes placed in the hierarchy so far
        self.node_objects = {}  # node index -> the Node made of it
        self.sourceless = set()  # the textures without a source image, warned about once each
        self.positionless = []  # the primitives without POSITION, left out (glTF: not drawn)
        self.triangle_count = 0  # of the primitives read so far
        self.mesh_nodes = {}  # glTF node index -> the Nodes drawing its primitives
        self.skinned = []  # (glTF node index, skin index) of the skinned nodes
        required = self.json.get(self.doc, "extensionsRequired", "", [], list)
        missing = [str(e) for e in required if e not in GLTF_EXTENSIONS]
        if missing:
            self.json.fail("extensionsRequired", f"needs {', '.join(missing)}, which vct does not read "
                                                 f"(it reads {', '.join(GLTF_EXTENSIONS)})")
        unread = sorted({str(e) for e in self.json.get(self.doc, "extensionsUsed", "", [], list)} - set(GLTF_EXTENSIONS))
        if unread:
            warn(f"uses extensions vct does not read, drawn without them: {', '.join(unread)}", source=name)

