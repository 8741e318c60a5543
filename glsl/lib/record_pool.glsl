// The records no voxel holds (engine/voxels/records.py): a stack of free records, its height
// first, then how many records a voxelization asked of it in vain.
layout(std430, binding = SSBO_RECORD_POOL) buffer RecordPool { int free_count; uint short_count; uint free_records[]; };

// Puts a record no voxel holds any more back on the stack (a stack too full to hold it is
// short: the grid is then made anew with more room, VoxelizePass.update).
void give_back_record(uint record) {
    int at = atomicAdd(free_count, 1);
    if (at >= 0 && at < free_records.length()) free_records[at] = record;
}
