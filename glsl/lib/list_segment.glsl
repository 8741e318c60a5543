// The segment of a list a pass runs over: row `segment` of a table of ListSegments that the
// GPU filled (engine/voxels/lists.py SegmentTable): entries segment_first() ..
// segment_first() + segment_count() - 1 of the list, and the size of the dispatch over them.
#include "engine_constants.glsl"

layout(std430, binding = SSBO_SEGMENTS) buffer Segments { ListSegment segments[]; };
uniform uint segment;

uint segment_first() { return segments[segment].range.x; }
uint segment_count() { return segments[segment].range.y; }

// Run `part` of `parts` equal runs of the segment's entries (0 of 1: all of them): the entry
// invocation i takes, false past the run. Runs keep the list's order (by block and facing for
// the class lists): a run of them is a region of the grid, its neighbouring invocations alike.
bool segment_run_entry(uint i, uint part, uint parts, out uint entry) {
    uint run_length = (segment_count() + parts - 1u) / parts;
    entry = part * run_length + i;
    return i < run_length && entry < segment_count();
}
