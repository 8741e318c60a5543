// Lists the GPU appends to (engine/voxels/lists.py VoxelList): a count, then as many entries as
// the buffer has room for. The count goes on past the room, so the host sees how many entries a
// list needed and grows it (VoxelGrid.grow_lists); the entries past the room are dropped, and
// readers stop at the room (LISTED).
#define APPEND(count, entries, entry) { uint slot_ = atomicAdd(count, 1u); if (slot_ < uint(entries.length())) entries[slot_] = (entry); }
#define LISTED(count, entries) min(count, uint(entries.length()))
