// The ring pass's commands program, one workgroup, after the place program's ring ranges: per bucket (material,
// side count, chunk kind) its indirect command (5 words: DrawElementsIndirectCommand) from its chunk count and its
// side slot and kind's template, and its first chunk, the cursor the place program places its chunk records from.
layout(std430, binding = RING_COMMANDS) writeonly buffer Commands { uint commands[]; };  // 5 words each, one per bucket
layout(std430, binding = RING_TEMPLATES) readonly buffer Templates { uvec2 templates[]; };  // (count, first index) per side slot and kind

void main() {
    uint first = 0u;
    for (uint base = 0u; base < u_buckets; base += kLanes) {  // uniform: every lane runs every batch
        uint b = base + gl_LocalInvocationID.x;
        uint count = b < u_buckets ? buckets[b] : 0u;
        uint total;
        uint at = first + lane_scan(count, total);
        if (b < u_buckets) {
            uvec2 t = templates[b % (6u * u_side_slots)];
            commands[5u * b] = t.x;
            commands[5u * b + 1u] = count;
            commands[5u * b + 2u] = t.y;
            commands[5u * b + 3u] = 0u;
            commands[5u * b + 4u] = at;
            buckets[u_buckets + b] = at;
        }
        first += total;
    }
}
