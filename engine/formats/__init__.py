"""Files in and out: the JSON scene format and its schema, glTF, OBJ/MTL, PLY and STL meshes,
scenes built in code and from trimesh, the bounded reading of every file a scene names, and the
images, sequences and videos a render writes."""
