#version 450 core
// The counting sorts' prefix sum (gather/sort_classes.comp, gather/sort_class_cells.comp): each
// bucket's count becomes its first entry in the sorted list (the sum of the counts before
// it), in place; then each segment row r spans buckets row_buckets[r] = [first, end) and gets
// their entries and the size of a dispatch over them. One workgroup: each invocation sums a
// run of buckets, the runs' sums are scanned, then each run is.
#include "lib/list_segment.glsl"

layout(local_size_x = SCAN_GROUP) in;
layout(std430, binding = SSBO_CLASS_BUCKETS) coherent buffer Buckets { uint buckets[]; };
uniform uint bucket_count;
uniform uint row_count;
uniform uvec2 row_buckets[MAX_SEGMENT_ROWS];

shared uint run_first[SCAN_GROUP];
shared uint total;

// The first entry of bucket b once scanned (the total past the last).
uint bucket_first(uint b) {
    return b < bucket_count ? buckets[b] : total;
}

void main() {
    uint t = gl_LocalInvocationID.x;
    uint run = (bucket_count + uint(SCAN_GROUP) - 1u) / uint(SCAN_GROUP);
    uint begin = min(t * run, bucket_count), end = min(begin + run, bucket_count);
    uint sum = 0u;
    for (uint b = begin; b < end; ++b) sum += buckets[b];
    run_first[t] = sum;
    barrier();
    if (t == 0u) {
        uint before = 0u;
        for (uint k = 0u; k < uint(SCAN_GROUP); ++k) {
            uint s = run_first[k];
            run_first[k] = before;
            before += s;
        }
        total = before;
    }
    barrier();
    uint first = run_first[t];
    for (uint b = begin; b < end; ++b) {
        uint count = buckets[b];
        buckets[b] = first;
        first += count;
    }
    memoryBarrierBuffer();
    barrier();
    if (t < row_count) {
        uint entries = bucket_first(row_buckets[t].x);
        uint count = bucket_first(row_buckets[t].y) - entries;
        segments[t].dispatch = uvec4((count + uint(LIST_GROUP) - 1u) / uint(LIST_GROUP), 1u, 1u, 0u);
        segments[t].range = uvec4(entries, count, 0u, 0u);
    }
}
