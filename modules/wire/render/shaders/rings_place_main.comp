// The ring pass's place program: one workgroup walking the dispatched wires kLanes at a time, in wire order, so
// where a wire's rings and chunk records land, which wires go coarse when the ring buffer is short and the order
// the draw meets the chunks in (instance order) are the same on every GPU and every frame, whatever order the
// GPU runs invocations in (atomics would hand them out in arrival order).
// u_stage 0, after the LOD program: each wire's range of the ring buffer (a prefix sum of the rings the jobs want);
// one past u_ring_capacity, or wanting more than u_max_wire_rings, a wire gets one ring a segment from the reserve
// (u_ring_reserve rings after the capacity; the wires past the capacity are the last in order), or none (not
// drawn) past that; the totals
// in Counter; with u_draw, each bucket's chunk count and the triangles the draw expands (sums: the same in any
// order). u_stage 1, after the commands program: with u_draw, the chunk records, each bucket's in wire order from
// its cursor.
layout(std430, binding = RING_COUNTER) buffer Counter {
    uint ring_counter; uint overflow; uint reserve_counter; uint triangles;
};  // rings wanted, wires past the capacity, reserve rings given, triangles (u_draw)
layout(std430, binding = RING_CHUNKS) writeonly buffer Chunks { uvec2 chunks[]; };
uniform uint u_stage;
uniform uint u_ring_capacity;
uniform uint u_ring_reserve;
uniform uint u_max_wire_rings;

const uint kNone = 0xffffffffu;  // no group: a lane without a wire, or a wire not drawn
shared uint s_group[kLanes], s_big[kLanes], s_bits[kLanes];  // stage 1: each lane's bucket group and chunk counts

void place_rings() {
    uint wanted = 0u, given = 0u;  // running totals (saturating), the same in every lane
    for (uint base = 0u; base < u_wires; base += kLanes) {
        uint w = base + gl_LocalInvocationID.x;
        uint n = w < u_wires ? jobs[w].ring_count : 0u;
        uint fewest = 0u;
        if (n != 0u) {
            load_wire(visible[w]);
            fewest = SEGS + (CLOSED ? 0u : 1u);
        }
        // More rings than one wire may have (kNodesPathMaxRings): from the reserve, taking none of the buffer.
        bool too_many = n > u_max_wire_rings;
        uint want = too_many ? 0u : n;
        uint total;
        uint first = sat_add(wanted, lane_scan(want, total));
        wanted = sat_add(wanted, total);
        bool over = n != 0u && (too_many || sat_add(first, want) > u_ring_capacity);  // u_ring_capacity < kSat
        uint reserve_first = sat_add(given, lane_scan(over ? fewest : 0u, total));
        given = sat_add(given, total);
        if (over) atomicAdd(overflow, 1u);  // a count: the same in any order
        // The rest without continue: every lane reaches the next batch's barriers by the same path (a barrier
        // must be in uniform control flow, and not every driver reconverges a loop after a divergent continue).
        if (n != 0u) {
            uint flags = jobs[w].flags & ~kJobFromReserve;
            if (over) {
                if (sat_add(reserve_first, fewest) <= u_ring_reserve) {
                    first = u_ring_capacity + reserve_first;
                    n = fewest;
                    flags |= kJobFromReserve;
                } else {
                    n = 0u;  // not drawn
                }
            }
            jobs[w].ring_first = first;
            jobs[w].ring_count = n;
            jobs[w].flags = flags;
        }
        if (u_draw && n != 0u) {
            uint material = H.flags >> kHeaderMaterialShift;
            bool caps = (H.flags & kHeaderCaps) != 0u;
            uint drawn = jobs[w].sides;
            for (uint kind = 0u; kind < 6u; ++kind) {
                uint c = chunk_count_of(kind, n, drawn, caps);
                if (c != 0u) atomicAdd(buckets[bucket_of(material, drawn, kind)], c);
            }
            uint bands = n - 1u + (CLOSED ? 1u : 0u);
            uint tris = drawn <= 2u ? 2u * bands : (2u * bands + (!CLOSED && caps ? 2u : 0u)) * drawn;
            if (tris != 0u) atomicAdd(triangles, tris);
        }
    }
    if (gl_LocalInvocationID.x == 0u) {
        ring_counter = wanted;
        reserve_counter = given;
    }
}

// Lane j of the batch, for a lane of `group`: an earlier lane of the group adds its chunks to the ranks, a later
// one means this lane is not the group's last.
void rank_of(uint j, uint lane, uint group, inout uint rank[6], inout bool last) {
    if (s_group[j] != group || j == lane) return;
    if (j > lane) {
        last = false;
        return;
    }
    uint bits = s_bits[j];
    rank[0] += bits & 1u;
    rank[1] += s_big[j];
    rank[2] += (bits >> 2u) & 1u;
    rank[3] += (bits >> 3u) & 1u;
    rank[4] += (bits >> 4u) & 1u;
    rank[5] += (bits >> 5u) & 1u;
}

void place_chunks() {
    uint lane = gl_LocalInvocationID.x;
    for (uint base = 0u; base < u_wires; base += kLanes) {
        uint w = base + lane;
        uint n = w < u_wires ? jobs[w].ring_count : 0u;
        uint group = kNone, c[6] = uint[6](0u, 0u, 0u, 0u, 0u, 0u);
        bool caps = false;
        uint material = 0u, drawn = 0u;
        if (n != 0u) {
            load_wire(visible[w]);
            material = H.flags >> kHeaderMaterialShift;
            caps = (H.flags & kHeaderCaps) != 0u;
            drawn = jobs[w].sides;
            group = material * u_side_slots + drawn;
            for (uint kind = 0u; kind < 6u; ++kind) c[kind] = chunk_count_of(kind, n, drawn, caps);
        }
        s_group[lane] = group;
        s_big[lane] = c[1];
        s_bits[lane] = c[0] | (c[2] << 2u) | (c[3] << 3u) | (c[4] << 4u) | (c[5] << 5u);
        memoryBarrierShared();
        barrier();
        // The chunks the batch's earlier lanes of the same group put in each of its buckets; whether a later
        // lane of the group follows (else this lane moves the cursors past the batch's chunks). 16 lanes an
        // iteration (rank_of written out): llvmpipe's 65,535 loop iterations an invocation then cover about a
        // million wires.
        uint rank[6] = uint[6](0u, 0u, 0u, 0u, 0u, 0u);
        bool last = true;
        if (group != kNone) {
            for (uint j = 0u; j < kLanes && (last || j <= lane); j += 16u) {
                rank_of(j, lane, group, rank, last);
                rank_of(j + 1u, lane, group, rank, last);
                rank_of(j + 2u, lane, group, rank, last);
                rank_of(j + 3u, lane, group, rank, last);
                rank_of(j + 4u, lane, group, rank, last);
                rank_of(j + 5u, lane, group, rank, last);
                rank_of(j + 6u, lane, group, rank, last);
                rank_of(j + 7u, lane, group, rank, last);
                rank_of(j + 8u, lane, group, rank, last);
                rank_of(j + 9u, lane, group, rank, last);
                rank_of(j + 10u, lane, group, rank, last);
                rank_of(j + 11u, lane, group, rank, last);
                rank_of(j + 12u, lane, group, rank, last);
                rank_of(j + 13u, lane, group, rank, last);
                rank_of(j + 14u, lane, group, rank, last);
                rank_of(j + 15u, lane, group, rank, last);
            }
        }
        uint at[6];
        for (uint kind = 0u; kind < 6u; ++kind)
            at[kind] = group != kNone ? buckets[u_buckets + group * 6u + kind] + rank[kind] : 0u;
        memoryBarrierBuffer();
        barrier();  // every lane has read the cursors
        if (group != kNone) {
            uint band = 0u;
            for (uint kind = 0u; kind < 6u; ++kind) {
                for (uint i = 0u; i < c[kind]; ++i) {
                    chunks[at[kind] + i] = uvec2(w, kind == 0u ? 0u : band);
                    if (kind != 0u) band += 16u >> (kind - 1u);
                }
                if (last) buckets[u_buckets + group * 6u + kind] = at[kind] + c[kind];
            }
        }
        memoryBarrierBuffer();
        barrier();  // the cursors moved before the next batch reads them
    }
}

void main() {
    if (u_stage == 0u) place_rings();
    else if (u_draw) place_chunks();
}
