// Packed ring records (wire::render::PackedRing, 7 words): centre xyz, radius, u (floats), frame quaternion in
// smallest-three form (2-bit index of the largest component, three 20-bit components).
layout(std430, binding = 1) readonly buffer Rings { uint ring_words[]; };
// cos and sin of 2 pi j / n for n = 3, 4, ... (n + 1 entries each, the last repeating j = 0), computed as
// wire::write_tube's side table (double, then float): the two paths place rim vertices identically.
layout(std430, binding = 2) readonly buffer Circle { vec2 circle[]; };
// One record per instance (a chunk of a wire, upload_plan.hpp): the wire's draw index and its first band.
layout(std430, binding = 3) readonly buffer Chunks { uvec2 chunks[]; };
vec2 circle_at(uint n, uint j) { return circle[n * (n + 1u) / 2u - 6u + j]; }
const uint kCapVertexBase = 1073741824u;  // 1 << 30: vertex ids of the two caps (kCapVertexBase in upload_plan.hpp)

struct Ring { vec3 centre_m; float radius_m; float u; vec3 normal; vec3 binormal; vec3 tangent; };

uint ring_base(GpuDraw d, uint i) { return d.ring_first + i * 7u; }
vec3 ring_centre(GpuDraw d, uint i) {
  uint b = ring_base(d, i);
  return vec3(uintBitsToFloat(ring_words[b]), uintBitsToFloat(ring_words[b + 1u]), uintBitsToFloat(ring_words[b + 2u]));
}
float ring_radius(GpuDraw d, uint i) { return uintBitsToFloat(ring_words[ring_base(d, i) + 3u]); }

float fixed20(uint k) { return (float(k) / 1048575.0 * 2.0 - 1.0) * 0.70710678; }

Ring load_ring(GpuDraw d, uint i) {
  uint b = ring_base(d, i);
  Ring r;
  r.centre_m = ring_centre(d, i);
  r.radius_m = uintBitsToFloat(ring_words[b + 3u]);
  r.u = uintBitsToFloat(ring_words[b + 4u]);
  uint w0 = ring_words[b + 5u], w1 = ring_words[b + 6u];
  uint largest = w0 & 3u;
  vec3 abc = vec3(fixed20((w0 >> 2u) & 1048575u), fixed20(((w0 >> 22u) | (w1 << 10u)) & 1048575u),
                  fixed20((w1 >> 10u) & 1048575u));
  float big = sqrt(max(0.0, 1.0 - dot(abc, abc)));
  vec4 q = largest == 0u ? vec4(big, abc) : largest == 1u ? vec4(abc.x, big, abc.yz)
         : largest == 2u ? vec4(abc.xy, big, abc.z) : vec4(abc, big);
  float x = q.x, y = q.y, z = q.z, w = q.w;
  r.normal = vec3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y));
  r.binormal = vec3(2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x));
  r.tangent = vec3(2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));
  return r;
}

// wire::write_tube's slope_at: central difference of radius over chord length, one-sided at open ends.
float slope_at(GpuDraw d, uint i, Ring ri) {
  uint n = d.ring_count;
  if ((d.flags & kDrawTilt) == 0u || n < 2u) return 0.0;
  bool closed = (d.flags & kDrawClosed) != 0u;
  uint lo = i > 0u ? i - 1u : (closed ? n - 1u : i);
  uint hi = i + 1u < n ? i + 1u : (closed ? 0u : i);
  float dr = ring_radius(d, hi) - ring_radius(d, lo);
  if (dr == 0.0) return 0.0;
  float ds = length(ring_centre(d, hi) - ri.centre_m) + length(ri.centre_m - ring_centre(d, lo));
  return ds > 0.0 ? clamp(dr / ds, -1e18, 1e18) : 0.0;  // as write_tube: 1 + slope^2 stays finite
}

// vid / m for m >= 4 without an integer division (software rasterizers run vector integer division one lane
// at a time): the float quotient is within 1 of the true one for vid < 2^24, then corrected exactly.
uint div_row(uint vid, uint m) {
  int q = int(float(vid) / float(m));
  int r = int(vid) - q * int(m);
  if (r < 0) q -= 1;
  else if (r >= int(m)) q += 1;
  return uint(q);
}

// Indexed: gl_VertexID is local_row * (n + 1) + s for the tube (row = the chunk's first band + local_row = ring,
// or ring_count for a closed wire's repeat of ring 0), kCapVertexBase + cap * (n + 1) + k for the caps (k = 0
// centre, 1 + j rim vertex j).
void main() {
  uvec2 chunk = chunks[record_index()];
  GpuDraw d = draws[chunk.x];
  uint n = d.sides;
  uint vid = uint(gl_VertexID);
  if (strip_mode(d) != 0u) {  // strip: vertex 2 row + (0: -side, 1: +side); a closed wire's last row repeats ring 0
    uint row = chunk.y + (vid >> 1u);
    uint i = row == d.ring_count ? 0u : row;
    Ring r = load_ring(d, i);
    float u = row == d.ring_count ? d.u_close : r.u;
    strip_vertex(d, strip_mode(d), r.centre_m, r.normal, r.binormal, r.tangent, r.radius_m, u, (vid & 1u) == 0u ? -1.0 : 1.0);
    return;
  }
  tube_outputs();
  vec3 pos;
  vec3 nrm;
  vec2 uv;
  if (vid < kCapVertexBase) {
    uint local_row = div_row(vid, n + 1u);
    uint s = vid - local_row * (n + 1u);
    uint row = chunk.y + local_row;
    uint i = row == d.ring_count ? 0u : row;  // a closed wire's last row repeats ring 0 ...
    Ring r = load_ring(d, i);
    float u = row == d.ring_count ? d.u_close : r.u;  // ... with u = u_close
    vec2 cs = circle_at(n, s);
    float cp = cs.x, sp = cs.y;
    float slope = slope_at(d, i, r);
    float a = 1.0 / sqrt(1.0 + slope * slope);
    vec3 tb = (slope * a) * r.tangent;
    pos = r.centre_m + (cp * (r.radius_m * r.normal) + sp * (r.radius_m * r.binormal));
    nrm = -tb + (cp * (a * r.normal) + sp * (a * r.binormal));
    uv = vec2(u, float(s) / float(n));
  } else {
    // Caps: start cap faces -t, end cap +t; the index pattern orders the triangles (centre, rim, rim).
    uint k = vid - kCapVertexBase;
    uint cap = k >= n + 1u ? 1u : 0u;
    uint c = k - cap * (n + 1u);
    Ring r = load_ring(d, cap == 0u ? 0u : d.ring_count - 1u);
    nrm = (cap == 0u ? -1.0 : 1.0) * r.tangent;
    if (c == 0u) {
      pos = r.centre_m;
      uv = vec2(0.5);
    } else {
      vec2 cs = circle_at(n, c - 1u);
      float cp = cs.x, sp = cs.y;
      pos = r.centre_m + (cp * (r.radius_m * r.normal) + sp * (r.radius_m * r.binormal));
      uv = vec2(0.5) + 0.5 * vec2(cp, sp);
    }
  }
  vec3 rel = d.offset_m + pos;
  v_rel_m = rel;
  v_normal = nrm;
  v_uv = uv;
  gl_Position = u_clip_from_rel * vec4(rel, 1.0);
}
