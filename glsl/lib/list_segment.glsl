// The segment of a list a pass runs over: row `segment` of a table of ListSegments that the
// GPU filled (engine/voxels/lists.py SegmentTable): entries segment_first() ..
// segment_first() + segment_count() - 1 of the list, and the size of the dispatch over them.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_SEGMENTS) buffer Segments { ListSegment segments[]; };
uniform uint segment;

uint segment_first() { return segments[segment].range.x; }
uint segment_count() { return segments[segment].range.y; }
