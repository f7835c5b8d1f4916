// The ring pass's commands program, one invocation after the LOD program: per bucket (material, side count, chunk
// kind) its indirect command (5 words: DrawElementsIndirectCommand) from its chunk count and its side slot and
// kind's template, and its first chunk, the cursor the rings program places its chunk records from.
layout(local_size_x = 1) in;
layout(std430, binding = RING_COMMANDS) writeonly buffer Commands { uint commands[]; };  // 5 words each, one per bucket
layout(std430, binding = RING_TEMPLATES) readonly buffer Templates { uvec2 templates[]; };  // (count, first index) per side slot and kind

void main() {
    uint first = 0u;
    for (uint b = 0u; b < u_buckets; ++b) {
        uint count = buckets[b];
        uvec2 t = templates[b % (6u * u_side_slots)];
        commands[5u * b] = t.x;
        commands[5u * b + 1u] = count;
        commands[5u * b + 2u] = t.y;
        commands[5u * b + 3u] = 0u;
        commands[5u * b + 4u] = first;
        buckets[u_buckets + b] = first;
        first += count;
    }
}
