// The ring pass's buckets (every program of it): one per (material, side count, chunk kind). The LOD program counts
// each bucket's chunks, the commands program turns the counts into indirect commands and first chunks, the rings
// program places its chunk records from those.
layout(std430, binding = RING_BUCKETS) buffer Buckets { uint buckets[]; };  // u_buckets chunk counts, then as many cursors
uniform uint u_buckets, u_side_slots;
