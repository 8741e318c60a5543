// The world box whose voxels the sky's light is made again at (SkyLightPass: near draws that
// move; all of space otherwise).
uniform vec3 lit_box_min;
uniform vec3 lit_box_max;

// Whether p lies in the box grown by `reach` on each side.
bool near_lit_box(vec3 p, float reach) {
    return all(greaterThanEqual(p, lit_box_min - reach)) && all(lessThanEqual(p, lit_box_max + reach));
}
