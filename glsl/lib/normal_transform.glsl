// What carries normals by a matrix: its cofactor matrix, the inverse transpose times the
// determinant, signed so that a mirroring matrix keeps normals on their side. Unlike the
// inverse it exists for a matrix that flattens an axis (the normal of the flattened shape).
mat3 normal_transform(mat3 m) {
    mat3 cofactors = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]));
    return dot(m[0], cofactors[0]) < 0.0 ? -cofactors : cofactors;
}
