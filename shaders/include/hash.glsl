// The lattice hash of the value noise and of the fur's strand roots: lowbias32 (C. Wellons,
// "Prospecting for hash functions", 2018) of the point's coordinates mixed by large primes, in
// [0, 1).  GLSL twin of workbench/core/noise.py's _hash3 (uint wraps as its uint32; a negative
// coordinate converts to uint by two's complement, as its int64 & 0xFFFFFFFF).
float hash3(ivec3 i) {
    uvec3 u = uvec3(i);
    uint h = (u.x * 73856093u) ^ (u.y * 19349663u) ^ (u.z * 83492791u);
    h ^= h >> 16u;
    h *= 0x7FEB352Du;
    h ^= h >> 15u;
    h *= 0x846CA68Bu;
    h ^= h >> 16u;
    return float(h >> 8u) / 16777216.0;
}
