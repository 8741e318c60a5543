"""Path-traced reference radiance for a vct scene, rendered with Mitsuba 3 (the renderer the
references in ../shared/reference came from), so any scene or variant can be checked the way
the Cornell box is:

    .venv/bin/pip install -e '.[reference]'
    .venv/bin/python tools/reference.py SCENE.json OUT.npy [--spp 1024] [--max-depth -1]
    .venv/bin/vct bench SCENE.json --reference OUT.npy      # or compare with `vct render --hdr`

The scene's triangles, Lambertian materials (albedo; emission as one-sided area emitters),
point/spot/directional lights and camera are converted as they are; the output is linear
float32 radiance (H, W, 3), row 0 at the top, each pixel integrated over its footprint (box
filter). `--max-depth 3` gives direct light + one bounce (Mitsuba counts the camera ray and
the emitter hit), `-1` all bounces.
"""
import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import engine  # noqa: E402
from engine import transforms  # noqa: E402


def rgb(value):
    return {"type": "rgb", "value": [float(v) for v in value]}


def scene_dict(scene, spp, max_depth, mesh_dir):
    import trimesh

    camera = scene.camera
    up = np.asarray(camera.up, float)
    sensor = {
        "type": "perspective", "fov": camera.vertical_fov_deg, "fov_axis": "y",
        "to_world": mi.ScalarTransform4f.look_at(origin=list(camera.position), target=list(camera.look_at), up=list(up)),
        "film": {"type": "hdrfilm", "width": camera.width, "height": camera.height, "rfilter": {"type": "box"},
                 "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": spp},
    }
    result = {"type": "scene", "integrator": {"type": "path", "max_depth": max_depth}, "sensor": sensor}
    for k, (node, world) in enumerate(scene.drawables()):
        material = node.material
        if material.metalness > 0 or material.specular > 0:
            raise engine.VctError("the reference supports Lambertian materials only", field=f"materials.{material.name}")
        path = Path(mesh_dir) / f"mesh{k}.ply"
        positions = transforms.transform_points(world, node.mesh.positions)
        trimesh.Trimesh(positions, node.mesh.indices, process=False).export(path)
        shape = {"type": "ply", "filename": str(path), "face_normals": True,
                 "bsdf": {"type": "diffuse", "reflectance": rgb(material.albedo)}}
        if np.any(material.emission > 0):
            shape["emitter"] = {"type": "area", "radiance": rgb(material.emission)}
        result[f"shape{k}"] = shape
    for k, (_, light) in enumerate(scene.lights()):
        if light.range > 0:
            raise engine.VctError("the reference has no light range", field="lights")
        if light.type == "point":
            emitter = {"type": "point", "position": list(light.position), "intensity": rgb(light.intensity)}
        elif light.type == "spot":
            # vct's spot falls off smoothly between the inner and outer angles, Mitsuba's linearly.
            emitter = {"type": "spot", "intensity": rgb(light.intensity), "cutoff_angle": light.outer_angle_deg,
                       "beam_width": light.inner_angle_deg,
                       "to_world": mi.ScalarTransform4f.look_at(origin=list(light.position),
                                                                target=list(light.position + light.direction),
                                                                up=[0, 1, 0] if abs(light.direction[1]) < 0.99 else [1, 0, 0])}
        else:
            emitter = {"type": "directional", "direction": list(light.direction), "irradiance": rgb(light.intensity)}
        result[f"light{k}"] = emitter
    return result


def main():
    global mi
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("out", help="output .npy (linear float32 radiance, row 0 at the top)")
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--max-depth", type=int, default=-1, help="-1: all bounces; 2: direct only; 3: + one bounce")
    args = parser.parse_args()
    import mitsuba as mi

    variant = "scalar_rgb"  # the LLVM variants need a libLLVM that Dr.Jit can drive; scalar always runs
    mi.set_variant(variant)
    scene = engine.load_scene(args.scene)
    with tempfile.TemporaryDirectory() as mesh_dir:
        loaded = mi.load_dict(scene_dict(scene, args.spp, args.max_depth, mesh_dir))
        image = np.array(mi.render(loaded), dtype=np.float32)[..., :3]
    engine.save_npy(args.out, image)
    print(f"wrote {args.out} ({image.shape[1]}x{image.shape[0]}, {args.spp} spp, max depth {args.max_depth}, "
          f"{variant}), mean radiance {image.reshape(-1, 3).mean(axis=0).round(4).tolist()}")


if __name__ == "__main__":
    main()
