// A number in [0, 1) that is the same for the same point and looks random from one point to the
// next (a hash of its bits, lowbias32 by Chris Wellons).
float point_hash(vec3 q) {
    uvec3 bits = floatBitsToUint(q);
    uint h = bits.x ^ (bits.y * 0x9e3779b9u) ^ (bits.z * 0x85ebca6bu);
    h ^= h >> 16; h *= 0x7feb352du; h ^= h >> 15; h *= 0x846ca68bu; h ^= h >> 16;
    return float(h >> 8) * (1.0 / 16777216.0);
}
