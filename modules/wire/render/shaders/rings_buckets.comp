// The ring pass's buckets: one per (material, side count, chunk kind). The place program counts each bucket's
// chunks, the commands program turns the counts into indirect commands and first chunks (the cursors), the place
// program places the chunk records from those, moving the cursors as it goes (coherent: its lanes read what the
// others wrote, after a barrier).
layout(std430, binding = RING_BUCKETS) coherent buffer Buckets { uint buckets[]; };  // u_buckets chunk counts, then as many cursors
uniform uint u_buckets, u_side_slots;
