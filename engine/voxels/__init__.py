"""The voxel grid the passes write and cones read: its levels and their placement (clipmap, room),
the records of the covered voxels and the lists of voxels and cells the passes run over."""
