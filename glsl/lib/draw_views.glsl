// The views of the draw list being drawn (engine/passes/cull.py): a shadow view, a voxelization
// job; each instance drawn names its own (lib/draws.glsl instance_view).
#include "engine_constants.glsl"

layout(std430, binding = SSBO_DRAW_VIEWS) readonly buffer DrawViews { DrawView views[]; };
