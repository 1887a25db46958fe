// GPU count of the distinct voxels hit by at least one ray (draw(count=True)).
// One bit per box voxel in the word layout of voxel_bits (bit x % 32 of word x / 32 of row
// (y, z)) after a uint counter; the program without counting compiles mark_seen() to nothing.
#pragma geoshade define COUNT_SEEN
#pragma geoshade define COUNT_BINDING
#if COUNT_SEEN
layout(std430, binding = COUNT_BINDING) buffer SeenVoxels {
    uint seen_count;
    uint seen[];
};

void mark_seen(ivec3 p) {
    uint words_per_row = uint((box_size.x + BITS_PER_WORD - 1) / BITS_PER_WORD);
    uint i = uint(p.x / BITS_PER_WORD) + words_per_row * (uint(p.y) + uint(box_size.y) * uint(p.z));
    uint bit = 1u << uint(p.x % BITS_PER_WORD);
    uint old = atomicOr(seen[i], bit);
    if ((old & bit) == 0u) atomicAdd(seen_count, 1u);
}
#else
void mark_seen(ivec3 p) {}
#endif
