"""The scene model, free of GL and of files: nodes, meshes, materials, lights, cameras and the
environment (model), animation channels, emissive surfaces as area lights (emitters), the scene
as arrays kept current from its edit log (table) and what changed between frames (changes)."""
