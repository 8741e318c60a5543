"""Voxel views: one level of the grid ray-marched from the camera at one mip level, as blocks:
the base radiance (emission + injected direct light), the mean normals or the albedo."""
from ..core.constants import SHADER_ENUMS
from .target import FullScreenPass

# What each voxel view shows (voxel_view/march_voxels.frag's SHOW_*).
SHOW = {"voxels": SHADER_ENUMS["SHOW"]["radiance"], "voxel-normals": SHADER_ENUMS["SHOW"]["normal"],
        "voxel-albedo": SHADER_ENUMS["SHOW"]["albedo"]}


def shown_values(grid, base, view):
    """The array of values a voxel view (or `Renderer.voxels`) shows: the base radiance `base`
    (InjectPass), or the grid's normals or albedo."""
    return {"voxels": base, "voxel-normals": grid.normal, "voxel-albedo": grid.albedo}[view]


class VoxelViewPass(FullScreenPass):
    FRAGMENT_SHADER = "voxel_view/march_voxels.frag"
    READS = ("TEX_VOXEL_INSPECT", "UBO_CAMERA")

    def render(self, grid, volume, view, mip, level, camera):
        """Ray-march `volume`, the values `view` shows as a dense volume of `grid` with its
        hardware mip chain (engine/voxels/inspection.py), at mip `mip` of grid level `level`."""
        self.program.set(**grid.uniforms(), show=SHOW[view], mip=float(mip), shown_level=level,
                         viewport_size=tuple(float(x) for x in self.target.size))
        return self.draw(TEX_VOXEL_INSPECT=volume, **camera.resources())
