// Level of detail by screen-space error: Wang counts at the hull's nearest depth, sides from the projected
// radius, per-wire and per-segment hull culling, hysteresis, and the screen-error measurement.
#include "wire/lod.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string_view>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(WIRE_LOD_NO_AVX2)
#define WIRE_LOD_AVX2 1
#include <immintrin.h>
#endif

namespace wire {
namespace {

constexpr double default_tolerance_px = 0.5;
constexpr uint32_t default_max_rings = 256;
constexpr uint32_t default_max_sides = 32;
constexpr double default_band = 0.25;

double tolerance_or_default(double tolerance_px) {
    // Below 1e-6 px a finer tolerance changes nothing on screen, and a denormal one underflows the world-space
    // bound (tolerance * z / focal) to 0 on some paths but not others (fuzz_lod: 2.2e-317 px).
    constexpr double min_tolerance_px = 1e-6;
    if (!(tolerance_px > 0.0)) return default_tolerance_px;
    return tolerance_px < min_tolerance_px ? min_tolerance_px : tolerance_px;
}

// Nearest depth (clamped to near) and off-axis factor k of one segment's control hull.
struct HullDepth {
    double z_min = 0.0;
    double k = 1.0;
};

// A segment's four control points in view space (x right, y up, z depth).
using ViewHull = std::array<glm::dvec3, 4>;

// World -> view as a rotation and a translation (lookAt is rigid), taken once per wire.
struct ViewTransform {
    glm::dmat3 rotation;
    glm::dvec3 translation;
    explicit ViewTransform(const LodView& view)
        : rotation(view.view_from_world), translation(view.view_from_world[3]) {}
    [[nodiscard]] glm::dvec3 operator()(const glm::dvec3& p) const {
        const glm::dvec3 q = rotation * p + translation;
        return {q.x, q.y, -q.z};
    }
    [[nodiscard]] ViewHull hull(const CubicBezier& c) const {
        return {(*this)(c.b0), (*this)(c.b1), (*this)(c.b2), (*this)(c.b3)};
    }
};

HullDepth hull_depth(const ViewHull& p, const LodView& view) {
    double z_min = std::numeric_limits<double>::infinity();
    double a = 0.0;
    double b = 0.0;
    bool in_front = true;
    for (const glm::dvec3& q : p) {
        z_min = std::min(z_min, q.z);
        if (q.z >= view.near_m) {
            a = std::max(a, std::abs(q.x) / q.z);
            b = std::max(b, std::abs(q.y) / q.z);
        } else {
            in_front = false;
        }
    }
    if (!in_front) {
        // Part of the hull is behind the near plane: x/z is unbounded there, but only on-screen points count.
        a = view.tan_half_x;
        b = view.tan_half_y;
    }
    a = std::min(a, view.tan_half_x);
    b = std::min(b, view.tan_half_y);
    HullDepth h;
    h.z_min = std::max(z_min, view.near_m);
    h.k = std::sqrt(1.0 + a * a + b * b);
    return h;
}

// The screen edges' factors of a view: sqrt(1 + t^2) of each half angle's tangent (a distance to a side plane
// per unit of inflation) and the off-axis factor at the corner, sqrt(1 + tx^2 + ty^2). Every wire of a frame
// asks for the same view's: the last view's are kept (the same operations on the same tangents: the same bits).
struct EdgeFactors {
    double tx = std::numeric_limits<double>::quiet_NaN(), ty = std::numeric_limits<double>::quiet_NaN();
    double sx = 1.0, sy = 1.0, corner = 1.0;
};
const EdgeFactors& edge_factors(const LodView& view) {
    thread_local EdgeFactors e;
    if (!(e.tx == view.tan_half_x && e.ty == view.tan_half_y)) {
        const double tx = view.tan_half_x, ty = view.tan_half_y;
        e = {tx, ty, std::sqrt(1.0 + tx * tx), std::sqrt(1.0 + ty * ty), std::sqrt(1.0 + tx * tx + ty * ty)};
    }
    return e;
}

// The frustum planes in view space, tested against points inflated by a radius: bit i is set when the point is
// farther than radius_m outside plane i (left, right, bottom, top, near, far: the planes of LodView::planes).
struct PlaneTest {
    double tx, ty, rx, ry, r, near, far;
    PlaneTest(const LodView& view, double radius_m) : PlaneTest(view, radius_m, edge_factors(view)) {}
    PlaneTest(const LodView& view, double radius_m, const EdgeFactors& f)
        : tx(view.tan_half_x), ty(view.tan_half_y), rx(radius_m * f.sx), ry(radius_m * f.sy), r(radius_m),
          near(view.near_m), far(view.far_m) {}
    [[nodiscard]] unsigned outside(const glm::dvec3& q) const {
        unsigned m = 0;
        m |= (q.x + q.z * tx < -rx) ? 1u : 0u;
        m |= (q.z * tx - q.x < -rx) ? 2u : 0u;
        m |= (q.y + q.z * ty < -ry) ? 4u : 0u;
        m |= (q.z * ty - q.y < -ry) ? 8u : 0u;
        m |= (q.z - near < -r) ? 16u : 0u;
        m |= (far - q.z < -r) ? 32u : 0u;
        return m;
    }
    // Planes that all four points are outside of (0: the inflated hull may meet the frustum).
    [[nodiscard]] unsigned outside(const ViewHull& h) const {
        return outside(h[0]) & outside(h[1]) & outside(h[2]) & outside(h[3]);
    }
};

uint32_t wang_px(const CubicBezier& c, const HullDepth& h, const LodView& view, double tolerance_px,
                 uint32_t max_rings, bool* clamped) {
    const double eps_world = tolerance_px * h.z_min / (view.focal_px * h.k);
    const uint32_t n = wang_ring_count(c, eps_world, max_rings);
    if (clamped != nullptr && n >= max_rings) {
        // Clamped only if max_rings is really short of what the bound needs.
        const double m = std::max(glm::length(c.b0 - 2.0 * c.b1 + c.b2), glm::length(c.b1 - 2.0 * c.b2 + c.b3));
        *clamped = !(std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world))) <= static_cast<double>(max_rings));
    }
    return n;
}

// Point-to-segment distance in 2D.
double distance_to_piece(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    double t = len2 > 0.0 ? glm::dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return glm::length(p - (a + t * ab));
}

// Pixel distance from p to the view-space piece a-b after clipping it to z >= near; infinity if nothing is left.
double distance_to_view_piece(const glm::dvec2& p_px, glm::dvec3 a, glm::dvec3 b, const LodView& view) {
    const double n = view.near_m;
    if (a.z < n && b.z < n) return std::numeric_limits<double>::infinity();
    if (a.z < n) a = a + (b - a) * ((n - a.z) / (b.z - a.z));
    if (b.z < n) b = b + (a - b) * ((n - b.z) / (a.z - b.z));
    a.z = std::max(a.z, n);
    b.z = std::max(b.z, n);
    return distance_to_piece(p_px, view.view_to_px(a), view.view_to_px(b));
}

}  // namespace

LodView LodView::perspective(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                             double fov_y_rad, double width_px, double height_px, double near_m, double far_m) {
    LodView v;
    v.eye_m = eye_m;
    v.view_from_world = glm::lookAt(eye_m, target_m, up);
    const double aspect = width_px / height_px;
    v.clip_from_world = glm::perspective(fov_y_rad, aspect, near_m, far_m) * v.view_from_world;
    v.tan_half_y = std::tan(0.5 * fov_y_rad);
    v.tan_half_x = v.tan_half_y * aspect;
    v.focal_px = 0.5 * height_px / v.tan_half_y;
    v.near_m = near_m;
    v.far_m = far_m;
    v.width_px = width_px;
    v.height_px = height_px;
    // Gribb & Hartmann, in double: rows of clip_from_world.
    const glm::dmat4 m = glm::transpose(v.clip_from_world);
    const std::array<glm::dvec4, 6> raw = {m[3] + m[0], m[3] - m[0], m[3] + m[1],
                                           m[3] - m[1], m[3] + m[2], m[3] - m[2]};
    for (std::size_t i = 0; i < 6; ++i) {
        v.planes[i] = raw[i] / glm::length(glm::dvec3(raw[i]));
    }
    return v;
}

glm::dvec3 LodView::to_view(const glm::dvec3& world_m) const {
    const glm::dvec4 q = view_from_world * glm::dvec4(world_m, 1.0);
    return {q.x, q.y, -q.z};
}

glm::dvec2 LodView::view_to_px(const glm::dvec3& view) const {
    return {0.5 * width_px + focal_px * view.x / view.z, 0.5 * height_px - focal_px * view.y / view.z};
}

bool hull_visible(std::span<const CubicBezier> segments, double radius_m, const LodView& view) {
    if (segments.empty()) return false;
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius_m);
    unsigned all = 63u;
    for (const CubicBezier& c : segments) {
        all &= planes.outside(tf.hull(c));
        if (all == 0) return true;
    }
    return false;
}

uint32_t segment_ring_count_px(const CubicBezier& segment, const LodView& view, double tolerance_px,
                               uint32_t max_rings) {
    return wang_px(segment, hull_depth(ViewTransform(view).hull(segment), view), view, tolerance_or_default(tolerance_px),
                   max_rings ? max_rings : default_max_rings, nullptr);
}

uint32_t sides_for_radius(double radius_m, double z_m, double k, const LodView& view, double tolerance_px,
                          uint32_t max_sides) {
    max_sides = std::max<uint32_t>(max_sides ? max_sides : default_max_sides, 3);
    const double eps = tolerance_or_default(tolerance_px);
    const double r_px = radius_m * view.focal_px * k / std::max(z_m, view.near_m);
    if (!(r_px > 0.0)) return 3;
    const double x = eps / r_px;
    if (x >= 2.0) return 3;  // the whole tube is within eps of its centre line
    // Three sides, the usual answer, without the acos: n <= 3 iff acos(1 - x) >= pi / 3 iff x >= 1/2. Above
    // 1/2 by the relative margin below, 1 - x (exact: Sterbenz) is below 1/2 by 5e-10, so acos(1 - x) exceeds
    // pi / 3 by ~6e-10 relative, far more than the rounding of acos and of the quotient (a few 1e-16): the
    // formula's n is at most 3 there and the result 3. Nearer 1/2 the formula decides (tested on dense radii).
    if (x > 0.5 * (1.0 + 1e-9)) return 3;
    const double n = std::ceil(std::numbers::pi / std::acos(1.0 - x));
    if (!(n < static_cast<double>(max_sides))) return max_sides;
    return std::max<uint32_t>(3, static_cast<uint32_t>(n));
}

uint32_t hysteresis_count(uint32_t old_count, uint32_t raw_count, double band) {
    if (old_count == 0 || raw_count >= old_count || band < 0.0) return raw_count;
    if (static_cast<double>(old_count) <= static_cast<double>(raw_count) * (1.0 + band) + 1.0) return old_count;
    return std::min(old_count, raw_count + 1 + raw_count / 8);
}

namespace {

/// Tube, strip (2) or line (1) for a projected radius. Hysteresis: a thinner mode used last update is kept
/// until the radius exceeds its threshold by the band (like the counts), so a wire at the switch distance does
/// not alternate between two modes while the camera drifts.
uint32_t drawn_sides_for(double radius_px, uint32_t sides, uint32_t old_drawn, const LodSettings& settings,
                         double band) {
    const double strip = settings.strip_radius_px == 0.0 ? 2.0 : settings.strip_radius_px;
    const double line = settings.line_radius_px == 0.0 ? 0.5 : settings.line_radius_px;
    const double keep = 1.0 + std::max(band, 0.0);
    if (line > 0.0 && (radius_px < line || (old_drawn == 1 && radius_px < line * keep))) return 1;
    if (strip > 0.0 && (radius_px < strip || (old_drawn == 2 && radius_px < strip * keep))) return 2;
    return sides;
}

void mark_culled(WireLod& lod, bool& changed) {
    changed = lod.visible || !lod.counts.empty();
    lod.visible = false;
    lod.counts.clear();
    lod.required.clear();
    lod.sides = 0;
    lod.required_sides = 0;
    lod.drawn_sides = 0;
    lod.radius_px = 0.0;
    lod.z_min_m = 0.0;
    lod.visible_segments = 0;
    lod.clamped_segments = 0;
    lod.changed_counts = 0;
    lod.spans = 0;
    lod.bounded = false;
    lod.coherence.valid = false;
}

// What the hull-depth kernel needs of the view: world -> view (ViewTransform's rotation, column-major, and
// translation), the near and far planes, the screen edges' tangents, and the plane test's inflated offsets
// (PlaneTest's rx, ry, r, negated).
struct HullConstants {
    double m[9], t[3];
    double near, far, tx, ty;
    double neg_rx, neg_ry, neg_r;
};

// What the span walk's ratio kernel needs (SpanMerger::ratio() for a whole level): the view transform as above,
// the tolerance factor c = focal / eps, the off-axis bounds (k of the wire's sphere, the screen-edge cap), the
// frustum and the inflation of a span's sphere by the tube radius.
struct RatioConstants {
    double m[9], t[3];
    double c, k, k_cap;
    double near, far, tx, ty, sx, sy, radius;
    bool inside, coarse_offscreen;
};

// std::min, std::max by value, as they compare (glm::min and glm::max too).
inline double min_of(double x, double y) { return y < x ? y : x; }
inline double max_of(double x, double y) { return x < y ? y : x; }

// Lanes for the span hierarchy's kernels (lod_span_kernels.inl): the kernels are written once over a lane type,
// L1 (one double: the scalar code), L2 (two doubles in an SSE2 register) or L4 (four in an AVX register, where
// the CPU has AVX2), so every lane does exactly the scalar arithmetic (each operation the IEEE one, correctly
// rounded, no fused multiply-add): results are bit-identical whichever runs. min_of / max_of / select keep the
// scalar comparisons' operand order (minpd(a, b) is a < b ? a : b), so NaN and signed zeros come out as in the
// scalar code. Besides arithmetic a lane type loads and stores `width` consecutive doubles, splits 2 width
// consecutive ones into the even and the odd ones, and reads `width` consecutive segments' control points.
struct L1 {
    static constexpr std::size_t width = 1;
    double v;
    static L1 splat(double x) { return {x}; }
    static L1 load(const double* p) { return {*p}; }
    static L1 evens(const double* p) { return {p[0]}; }
    static L1 odds(const double* p) { return {p[1]}; }
    void store(double* p) const { *p = v; }
    // x, y, z of the four control points of one segment per lane (p: lane 0's segment, 12 doubles a segment).
    static void points(const double* p, L1 (&x)[4], L1 (&y)[4], L1 (&z)[4]) {
        for (int k = 0; k < 4; ++k) x[k] = {p[3 * k]}, y[k] = {p[3 * k + 1]}, z[k] = {p[3 * k + 2]};
    }
};
struct M1 {
    bool v;
    [[nodiscard]] unsigned bits() const { return v ? 1u : 0u; }  // bit k: lane k
};
inline M1 operator&(M1 a, M1 b) { return {a.v && b.v}; }
inline M1 operator|(M1 a, M1 b) { return {a.v || b.v}; }
inline L1 neg_of(L1 a) { return {-a.v}; }
inline L1 operator+(L1 a, L1 b) { return {a.v + b.v}; }
inline L1 operator-(L1 a, L1 b) { return {a.v - b.v}; }
inline L1 operator*(L1 a, L1 b) { return {a.v * b.v}; }
inline L1 operator/(L1 a, L1 b) { return {a.v / b.v}; }
inline M1 operator<(L1 a, L1 b) { return {a.v < b.v}; }
inline M1 operator<=(L1 a, L1 b) { return {a.v <= b.v}; }
inline L1 sqrt_of(L1 a) { return {std::sqrt(a.v)}; }
inline L1 abs_of(L1 a) { return {std::abs(a.v)}; }
inline L1 min_of(L1 x, L1 y) { return {min_of(x.v, y.v)}; }
inline L1 max_of(L1 x, L1 y) { return {max_of(x.v, y.v)}; }
inline L1 select(M1 m, L1 a, L1 b) { return {m.v ? a.v : b.v}; }
inline L1 ceil_of(L1 a) { return {std::ceil(a.v)}; }

#if defined(__SSE2__)
struct L2 {
    static constexpr std::size_t width = 2;
    __m128d v;
    static L2 splat(double x) { return {_mm_set1_pd(x)}; }
    static L2 load(const double* p) { return {_mm_loadu_pd(p)}; }
    static L2 evens(const double* p) { return {_mm_unpacklo_pd(_mm_loadu_pd(p), _mm_loadu_pd(p + 2))}; }
    static L2 odds(const double* p) { return {_mm_unpackhi_pd(_mm_loadu_pd(p), _mm_loadu_pd(p + 2))}; }
    void store(double* p) const { _mm_storeu_pd(p, v); }
    static void points(const double* p, L2 (&x)[4], L2 (&y)[4], L2 (&z)[4]) {
        L2 c[12];
        for (int k = 0; k < 12; k += 2) {
            const __m128d a = _mm_loadu_pd(p + k), b = _mm_loadu_pd(p + 12 + k);
            c[k] = {_mm_unpacklo_pd(a, b)};
            c[k + 1] = {_mm_unpackhi_pd(a, b)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M2 {
    __m128d v;
    [[nodiscard]] unsigned bits() const { return static_cast<unsigned>(_mm_movemask_pd(v)); }
};
inline M2 operator&(M2 a, M2 b) { return {_mm_and_pd(a.v, b.v)}; }
inline M2 operator|(M2 a, M2 b) { return {_mm_or_pd(a.v, b.v)}; }
inline L2 neg_of(L2 a) { return {_mm_xor_pd(_mm_set1_pd(-0.0), a.v)}; }
inline L2 operator+(L2 a, L2 b) { return {_mm_add_pd(a.v, b.v)}; }
inline L2 operator-(L2 a, L2 b) { return {_mm_sub_pd(a.v, b.v)}; }
inline L2 operator*(L2 a, L2 b) { return {_mm_mul_pd(a.v, b.v)}; }
inline L2 operator/(L2 a, L2 b) { return {_mm_div_pd(a.v, b.v)}; }
inline M2 operator<(L2 a, L2 b) { return {_mm_cmplt_pd(a.v, b.v)}; }
inline M2 operator<=(L2 a, L2 b) { return {_mm_cmple_pd(a.v, b.v)}; }
inline L2 sqrt_of(L2 a) { return {_mm_sqrt_pd(a.v)}; }
inline L2 abs_of(L2 a) { return {_mm_andnot_pd(_mm_set1_pd(-0.0), a.v)}; }
inline L2 min_of(L2 x, L2 y) { return {_mm_min_pd(y.v, x.v)}; }  // y < x ? y : x
inline L2 max_of(L2 x, L2 y) { return {_mm_max_pd(y.v, x.v)}; }  // y > x ? y : x, i.e. x < y ? y : x
inline L2 select(M2 m, L2 a, L2 b) { return {_mm_or_pd(_mm_and_pd(m.v, a.v), _mm_andnot_pd(m.v, b.v))}; }
// std::ceil for x >= 0 (and NaN), without SSE4.1's rounding: below 2^52, (x + 2^52) - 2^52 is x rounded to an
// integer (both operations exact: the sum's spacing is 1), raised by 1 where that fell below x; from 2^52 on
// (and for +inf) x is an integer already, and a NaN stays NaN (the last select).
inline L2 ceil_of(L2 x) {
    const L2 big = L2::splat(0x1p52);
    const L2 t = (x + big) - big;
    return select(x < big, select(t < x, t + L2::splat(1.0), t), x);
}
namespace span_sse2 {
using W = L2;
#include "lod_span_kernels.inl"
}  // namespace span_sse2
#else
namespace span_sse2 {
using W = L1;
#include "lod_span_kernels.inl"
}  // namespace span_sse2
#endif

#if defined(WIRE_LOD_AVX2)
// The same kernels four lanes wide, compiled for AVX2 (no FMA: the arithmetic stays the scalar code's) and chosen
// at run time where the CPU has it.
#pragma GCC push_options
#pragma GCC target("avx2")
struct L4 {
    static constexpr std::size_t width = 4;
    __m256d v;
    static L4 splat(double x) { return {_mm256_set1_pd(x)}; }
    static L4 load(const double* p) { return {_mm256_loadu_pd(p)}; }
    // unpacklo of p0..3 and p4..7 is p0 p4 p2 p6; lanes (0, 2, 1, 3) of it are p0 p2 p4 p6.
    static L4 evens(const double* p) {
        return {_mm256_permute4x64_pd(_mm256_unpacklo_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)), 0xD8)};
    }
    static L4 odds(const double* p) {
        return {_mm256_permute4x64_pd(_mm256_unpackhi_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)), 0xD8)};
    }
    void store(double* p) const { _mm256_storeu_pd(p, v); }
    // Three 4 x 4 transposes: rows are the lanes' segments, columns 4 consecutive doubles of them.
    static void points(const double* p, L4 (&x)[4], L4 (&y)[4], L4 (&z)[4]) {
        L4 c[12];
        for (int k = 0; k < 12; k += 4) {
            const __m256d r0 = _mm256_loadu_pd(p + k), r1 = _mm256_loadu_pd(p + 12 + k);
            const __m256d r2 = _mm256_loadu_pd(p + 24 + k), r3 = _mm256_loadu_pd(p + 36 + k);
            const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
            const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
            c[k] = {_mm256_permute2f128_pd(t0, t2, 0x20)};
            c[k + 1] = {_mm256_permute2f128_pd(t1, t3, 0x20)};
            c[k + 2] = {_mm256_permute2f128_pd(t0, t2, 0x31)};
            c[k + 3] = {_mm256_permute2f128_pd(t1, t3, 0x31)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M4 {
    __m256d v;
    [[nodiscard]] unsigned bits() const { return static_cast<unsigned>(_mm256_movemask_pd(v)); }
};
inline M4 operator&(M4 a, M4 b) { return {_mm256_and_pd(a.v, b.v)}; }
inline M4 operator|(M4 a, M4 b) { return {_mm256_or_pd(a.v, b.v)}; }
inline L4 neg_of(L4 a) { return {_mm256_xor_pd(_mm256_set1_pd(-0.0), a.v)}; }
inline L4 operator+(L4 a, L4 b) { return {_mm256_add_pd(a.v, b.v)}; }
inline L4 operator-(L4 a, L4 b) { return {_mm256_sub_pd(a.v, b.v)}; }
inline L4 operator*(L4 a, L4 b) { return {_mm256_mul_pd(a.v, b.v)}; }
inline L4 operator/(L4 a, L4 b) { return {_mm256_div_pd(a.v, b.v)}; }
inline M4 operator<(L4 a, L4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ)}; }
inline M4 operator<=(L4 a, L4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LE_OQ)}; }
inline L4 sqrt_of(L4 a) { return {_mm256_sqrt_pd(a.v)}; }
inline L4 abs_of(L4 a) { return {_mm256_andnot_pd(_mm256_set1_pd(-0.0), a.v)}; }
inline L4 min_of(L4 x, L4 y) { return {_mm256_min_pd(y.v, x.v)}; }
inline L4 max_of(L4 x, L4 y) { return {_mm256_max_pd(y.v, x.v)}; }
inline L4 select(M4 m, L4 a, L4 b) { return {_mm256_blendv_pd(b.v, a.v, m.v)}; }
inline L4 ceil_of(L4 a) { return {_mm256_ceil_pd(a.v)}; }
namespace span_avx2 {
using W = L4;
#include "lod_span_kernels.inl"
}  // namespace span_avx2
#pragma GCC pop_options
#endif

#if defined(WIRE_LOD_AVX2)
// Eight lanes (AVX-512F), where the CPU has it; the same kernels again.
#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC diagnostic push
// GCC 12 warns about the intrinsics' own _mm512_undefined_pd() pass-through operands (a known false positive).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
struct L8 {
    static constexpr std::size_t width = 8;
    __m512d v;
    static L8 splat(double x) { return {_mm512_set1_pd(x)}; }
    static L8 load(const double* p) { return {_mm512_loadu_pd(p)}; }
    static L8 evens(const double* p) {
        const __m512i idx = _mm512_set_epi64(14, 12, 10, 8, 6, 4, 2, 0);
        return {_mm512_permutex2var_pd(_mm512_loadu_pd(p), idx, _mm512_loadu_pd(p + 8))};
    }
    static L8 odds(const double* p) {
        const __m512i idx = _mm512_set_epi64(15, 13, 11, 9, 7, 5, 3, 1);
        return {_mm512_permutex2var_pd(_mm512_loadu_pd(p), idx, _mm512_loadu_pd(p + 8))};
    }
    void store(double* p) const { _mm512_storeu_pd(p, v); }
    // L4's 4 x 4 transposes on segments s and s + 4 at once: row s holds doubles k .. k + 3 of segment s in its
    // low half and of segment s + 4 in its high half; the in-lane unpacks transpose both halves' 2 x 2 blocks,
    // and one two-source permute per output puts the blocks of segments 0 .. 7 in order.
    static void points(const double* p, L8 (&x)[4], L8 (&y)[4], L8 (&z)[4]) {
        const __m512i even_blocks = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);  // a0 b0 a2 b2 (2-double blocks)
        const __m512i odd_blocks = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);  // a1 b1 a3 b3
        L8 c[12];
        for (int k = 0; k < 12; k += 4) {
            __m512d r[4];
            for (int s = 0; s < 4; ++s)
                r[s] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(p + 12 * s + k)),
                                          _mm256_loadu_pd(p + 12 * (s + 4) + k), 1);
            const __m512d t0 = _mm512_unpacklo_pd(r[0], r[1]), t1 = _mm512_unpackhi_pd(r[0], r[1]);
            const __m512d t2 = _mm512_unpacklo_pd(r[2], r[3]), t3 = _mm512_unpackhi_pd(r[2], r[3]);
            c[k] = {_mm512_permutex2var_pd(t0, even_blocks, t2)};
            c[k + 1] = {_mm512_permutex2var_pd(t1, even_blocks, t3)};
            c[k + 2] = {_mm512_permutex2var_pd(t0, odd_blocks, t2)};
            c[k + 3] = {_mm512_permutex2var_pd(t1, odd_blocks, t3)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M8 {
    __mmask8 v;
    [[nodiscard]] unsigned bits() const { return v; }
};
inline M8 operator&(M8 a, M8 b) { return {static_cast<__mmask8>(a.v & b.v)}; }
inline M8 operator|(M8 a, M8 b) { return {static_cast<__mmask8>(a.v | b.v)}; }
inline L8 operator+(L8 a, L8 b) { return {_mm512_add_pd(a.v, b.v)}; }
inline L8 operator-(L8 a, L8 b) { return {_mm512_sub_pd(a.v, b.v)}; }
inline L8 operator*(L8 a, L8 b) { return {_mm512_mul_pd(a.v, b.v)}; }
inline L8 operator/(L8 a, L8 b) { return {_mm512_div_pd(a.v, b.v)}; }
inline M8 operator<(L8 a, L8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)}; }
inline M8 operator<=(L8 a, L8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)}; }
inline L8 sqrt_of(L8 a) { return {_mm512_sqrt_pd(a.v)}; }
inline L8 abs_of(L8 a) { return {_mm512_abs_pd(a.v)}; }
inline L8 neg_of(L8 a) {
    return {_mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(a.v), _mm512_set1_epi64(INT64_MIN)))};
}
inline L8 min_of(L8 x, L8 y) { return {_mm512_min_pd(y.v, x.v)}; }
inline L8 max_of(L8 x, L8 y) { return {_mm512_max_pd(y.v, x.v)}; }
inline L8 select(M8 m, L8 a, L8 b) { return {_mm512_mask_blend_pd(m.v, b.v, a.v)}; }
inline L8 ceil_of(L8 a) { return {_mm512_roundscale_pd(a.v, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)}; }
namespace span_avx512 {
using W = L8;
#define WIRE_LOD_TAIL4 1
#include "lod_span_kernels.inl"
#undef WIRE_LOD_TAIL4
}  // namespace span_avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options
#endif

// The span kernels for this CPU.
struct SpanKernels {
    void (*level0)(const CubicBezier*, std::size_t, double*, double*, double*, double*, double*);
    void (*merge_level)(const double*, const double*, std::size_t, double*, double*, std::size_t, double*);
    void (*merge_deviations)(const double*, const double*, std::size_t, double*, double*, std::size_t, double*);
    void (*merge_spheres)(const double*, std::size_t, double*, std::size_t);
    void (*hull_depths)(const CubicBezier*, std::size_t, const HullConstants&, double*, double*, unsigned char*);
    void (*wang_counts)(const double*, const double*, const double*, std::size_t, double, double, double*, double*);
    void (*ratios)(const double*, std::size_t, const RatioConstants&, double*);
    void (*box)(const CubicBezier*, std::size_t, double*, double*);
};
// The widest the CPU has; WIRE_LOD_LANES=2 or 4 in the environment caps the width (to compare the paths: every
// width gives the same bits).
SpanKernels choose_span_kernels() {
#if defined(WIRE_LOD_AVX2)
    // Only "2" and "4" cap the width; anything else (unset, or not one of those) leaves the widest.
    const char* cap = std::getenv("WIRE_LOD_LANES");
    const std::string_view lanes_text = cap != nullptr ? cap : "";
    const int lanes = lanes_text == "2" ? 2 : lanes_text == "4" ? 4 : 8;
    __builtin_cpu_init();
    if (lanes >= 8 && __builtin_cpu_supports("avx512f"))
        return {span_avx512::span_level0, span_avx512::span_merge_level, span_avx512::span_merge_deviations, span_avx512::span_merge_spheres, span_avx512::hull_depth_kernel,
                span_avx512::wang_counts, span_avx512::span_ratios, span_avx512::wire_box};
    if (lanes >= 4 && __builtin_cpu_supports("avx2"))
        return {span_avx2::span_level0, span_avx2::span_merge_level, span_avx2::span_merge_deviations, span_avx2::span_merge_spheres, span_avx2::hull_depth_kernel,
                span_avx2::wang_counts, span_avx2::span_ratios, span_avx2::wire_box};
#endif
    return {span_sse2::span_level0, span_sse2::span_merge_level, span_sse2::span_merge_deviations, span_sse2::span_merge_spheres, span_sse2::hull_depth_kernel,
            span_sse2::wang_counts, span_sse2::span_ratios, span_sse2::wire_box};
}
const SpanKernels& span_kernels() {
    static const SpanKernels kernels = choose_span_kernels();
    return kernels;
}

// Per-update working memory of one thread (grows once, then reused).
struct Scratch {
    std::vector<double> z_min, k;  // per segment: hull depth and off-axis factor (hull_depths())
    std::vector<double> raw, clamped;  // per segment: Wang's count and clamp flag (wang_counts())
    std::vector<double> ratios;        // per hierarchy node: SpanMerger's ratios
    std::vector<unsigned char> outside;
    std::vector<uint32_t> old_counts;
    std::vector<uint32_t> walk_a, walk_b;  // SpanMerger::walk_levels: the undecided nodes of two levels
};
Scratch& scratch() {
    thread_local Scratch s;
    return s;
}

// The span hierarchy walk: one pass over the nodes from the root, merging into one ring interval every node
// whose chord deviation meets the tolerance: for `required` at the tolerance itself, for `counts` at the
// hysteresis threshold (1 for a span merged in `old`, 1 / (1 + band) for a new one; never looser, so a counts
// span always lies inside a required span). A node costs one depth (a dot product) when the wire's sphere is
// inside the frustum; otherwise its inflated sphere is also tested against the planes (an off-screen span is
// one interval).
class SpanMerger {
public:
    // inside: the wire's sphere lies inside the frustum, and k bounds the off-axis factor over it.
    SpanMerger(const LodBounds& b, const LodView& view, double eps, bool inside, double k, bool closed,
               bool coarse_offscreen, double new_span_scale, std::span<const uint32_t> old)
        : b_(b),
          view_(view),
          tf_(view),
          c_(view.focal_px / eps),
          k_(k),
          k_cap_(edge_factors(view).corner),
          closed_(closed),
          inside_(inside),
          coarse_offscreen_(coarse_offscreen),
          new_scale_(new_span_scale),
          old_(old),
          sx_(edge_factors(view).sx),
          sy_(edge_factors(view).sy) {}

    // ratio() of every node of a level at once (a lane kernel), computed when the walk first needs the level.
    [[nodiscard]] double level_ratio(std::size_t level, std::size_t j) const {
        if (((ready_ >> level) & 1u) == 0) fill_level_ratios(level);
        const std::size_t s = first(level, j), e = last(level, j);
        if (e - s > 1 && closed_ && 3 * (e - s) > b_.segments) {
            return std::numeric_limits<double>::infinity();  // a loop keeps >= 3 intervals
        }
        return ratios_[b_.level_start[level] + j];
    }
    // Out of line: once per level, so the walk's own frame stays small.
    [[gnu::noinline]] void fill_level_ratios(std::size_t level) const {
        {
            if (ratios_.size() < b_.data.size()) ratios_.resize(b_.data.size());
            RatioConstants rc{};
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r) rc.m[3 * c + r] = tf_.rotation[c][r];
            for (int r = 0; r < 3; ++r) rc.t[r] = tf_.translation[r];
            rc.c = c_;
            rc.k = k_;
            rc.k_cap = k_cap_;
            rc.near = view_.near_m;
            rc.far = view_.far_m;
            rc.tx = view_.tan_half_x;
            rc.ty = view_.tan_half_y;
            rc.sx = sx_;
            rc.sy = sy_;
            rc.radius = b_.radius_max_m;
            rc.inside = inside_;
            rc.coarse_offscreen = coarse_offscreen_;
            span_kernels().ratios(b_.level_data(level), b_.level_width(level), rc,
                                  ratios_.data() + b_.level_start[level]);
            ready_ |= uint64_t{1} << level;
        }
    }

    [[nodiscard]] std::size_t root_level() const { return b_.levels - 1; }
    [[nodiscard]] std::size_t first(std::size_t level, std::size_t j) const { return j << level; }
    [[nodiscard]] std::size_t last(std::size_t level, std::size_t j) const {
        return std::min((j + 1) << level, b_.segments);
    }

    // Deviation over the tolerance at the node's nearest depth (<= 1: one interval meets the tolerance).
    [[nodiscard]] double ratio(std::size_t level, std::size_t j) const {
        const std::size_t s = first(level, j), e = last(level, j);
        if (e - s > 1 && closed_ && 3 * (e - s) > b_.segments) {
            return std::numeric_limits<double>::infinity();  // a loop keeps >= 3 intervals
        }
        const SpanNode node = b_.node(level, j);
        const glm::dvec3 p = node.centre_m;
        const double r = node.radius_m;
        const glm::dmat3& m = tf_.rotation;
        const double z = -((m[0][2] * p.x + m[1][2] * p.y + m[2][2] * p.z) + tf_.translation.z);
        if (!inside_) {
            // Part of the wire is off screen: a span's chord may leave the screen, where the screen-edge cap
            // of the off-axis factor does not hold; bound it over the span's own sphere instead (uncapped).
            const glm::dvec3 q = tf_(p);
            if (coarse_offscreen_) {
                const double ri = r + b_.radius_max_m;
                const bool out =
                    q.x + q.z * view_.tan_half_x < -ri * sx_ || q.z * view_.tan_half_x - q.x < -ri * sx_ ||
                    q.y + q.z * view_.tan_half_y < -ri * sy_ || q.z * view_.tan_half_y - q.y < -ri * sy_ ||
                    q.z - view_.near_m < -ri || view_.far_m - q.z < -ri;
                if (out) return 0.0;
            }
            double k = k_cap_;  // a span reaching behind the near plane: clamped as the per-segment pass does
            if (z - r >= view_.near_m) {
                const double a = (std::abs(q.x) + r) / (z - r), b = (std::abs(q.y) + r) / (z - r);
                k = std::sqrt(1.0 + a * a + b * b);
            }
            return node.deviation_m * c_ * k / std::max(z - r, view_.near_m);
        }
        return node.deviation_m * c_ * k_ / std::max(z - r, view_.near_m);
    }

    // Smallest factor by which any ratio decided so far may change before crossing a threshold (1 or the new
    // span threshold).
    // Each ratio r contributes min(max(r, 1/r), max(r/s, s/r)) (s = new_scale_). max(r, 1/r) is r for r >= 1 and
    // 1/r below, both monotone in r (a correctly rounded quotient is monotone in its operands), so its smallest
    // value over the ratios is taken at the smallest r >= 1 or the largest r < 1; the same holds around s. The walk
    // keeps those four ratios (compares, no division per node) and margin() evaluates them: the same value.
    void note(double r) const {
        if (noting_) note_into(r, new_scale_, above_one_, below_one_, above_scale_, below_scale_);
    }
    // No margin() wanted (no Coherence is kept): the ratios are not noted.
    void skip_margin() { noting_ = false; }
    static void note_into(double r, double scale, double& above_one, double& below_one, double& above_scale,
                          double& below_scale) {
        // Branch-free (the sides of 1 and s alternate unpredictably along the walk): std::min / std::max as selects.
        const bool ok = r > 0.0 && r <= std::numeric_limits<double>::max();  // positive and finite
        above_one = ok && r >= 1.0 && r < above_one ? r : above_one;
        below_one = ok && r < 1.0 && below_one < r ? r : below_one;
        above_scale = ok && r >= scale && r < above_scale ? r : above_scale;
        below_scale = ok && r < scale && below_scale < r ? r : below_scale;
    }
    // A level-wide ratio (set_depth_range) contributes max(r, 1/r) alone: kept the same way.
    void note_level(double r) {
        if (!noting_ || !(r > 0.0) || !std::isfinite(r)) return;
        if (r >= 1.0) {
            level_above_one_ = std::min(level_above_one_, r);
        } else {
            level_below_one_ = std::max(level_below_one_, r);
        }
    }
    [[nodiscard]] double margin() const {
        double m = std::numeric_limits<double>::infinity();
        for (const double r : {level_above_one_, level_below_one_}) {
            if (!(r > 0.0) || !std::isfinite(r)) continue;  // no ratio on that side
            m = std::min(m, std::max(r, 1.0 / r));
        }
        for (const double r : {above_one_, below_one_, above_scale_, below_scale_}) {
            if (!(r > 0.0) || !std::isfinite(r)) continue;
            m = std::min({m, std::max(r, 1.0 / r), std::max(r / new_scale_, new_scale_ / r)});
        }
        return m;
    }

    [[nodiscard]] double counts_scale(std::size_t level, std::size_t j) const {
        return was_merged(first(level, j), last(level, j)) ? 1.0 : new_scale_;
    }

    // For a wire inside the frustum: its depth range [z_lo, z_hi] decides whole levels of the hierarchy from
    // the per-level deviation range, so the walk evaluates only the levels in between (usually one or two).
    // Only the `built` lowest levels are read (update_lod_once(): the levels above fail, and cannot fit).
    void set_depth_range(double z_lo, double z_hi, std::size_t built) {
        if (!inside_) return;
        const std::size_t levels = b_.levels;
        fit_level_ = -1;
        fail_level_ = levels;
        const double zh = std::max(z_hi, view_.near_m);
        const double fit_den = new_scale_ * z_lo;
        for (std::size_t l = 0; l < std::min(levels, built); ++l) {
            const bool loop_limit = l > 0 && closed_ && 3 * (std::size_t{1} << l) > b_.segments;
            // fit = fit_num / fit_den, fail = fail_num / zh, compared with 1 (divided only when noted).
            const double fit_num = b_.level_deviation_max(l) * c_ * k_;
            const double fail_num = b_.level_deviation_min(l) * c_ * k_;
            if (!loop_limit && quotient_at_most_one(fit_num, fit_den)) {
                fit_level_ = static_cast<std::ptrdiff_t>(l);
            }
            if (quotient_above_one(fail_num, zh) && fail_level_ == levels) fail_level_ = l;
            if (noting_) {
                if (!loop_limit) note_level(fit_num / fit_den);
                note_level(fail_num / zh);
            }
        }
    }
    // The rounded quotient num / den against 1 without dividing where den is positive and finite: num <= den then
    // decides it exactly. If num > den, num is at least den's next double, so num / den >= 1 + ulp(den) / den >
    // 1 + 2^-53 and rounds above 1; if num <= den the quotient is <= 1 and so is its rounding; NaN fails both ways.
    static bool quotient_at_most_one(double num, double den) {
        if (den > 0.0 && den <= std::numeric_limits<double>::max()) return num <= den;
        return num / den <= 1.0;
    }
    static bool quotient_above_one(double num, double den) {
        if (den > 0.0 && den <= std::numeric_limits<double>::max()) return num > den;
        return num / den > 1.0;
    }

    // Writes the spans into `required` and `counts` (other segments keep their values). Returns the number of
    // counts intervals that cross more than one segment.
    uint32_t apply(std::vector<uint32_t>& required, std::vector<uint32_t>& counts) const {
        return noting_ ? walk_levels<false, true>(required.data(), counts.data(), nullptr)
                       : walk_levels<false, false>(required.data(), counts.data(), nullptr);
    }
    // True when the walk writes every segment of both arrays (a span over each): the depth range decided a level
    // (every node that reaches it takes a span) and the walk runs. apply_zeroed() may then be used instead.
    [[nodiscard]] bool writes_every_segment() const { return fit_level_ >= 0 && fail_level_ != 0 && b_.levels > 0; }
    // apply() on arrays that are all 0: only the spans' first entries are written (the rest already hold 0).
    // `changed`: the entries of counts that now differ from the old counts (each old entry is a new 0 but a span's
    // first, which is a 1): the old non-zero entries, corrected at the spans' first entries during the walk, so
    // that the counts just written are not read back.
    uint32_t apply_zeroed(std::vector<uint32_t>& required, std::vector<uint32_t>& counts, uint32_t& changed) const {
        uint32_t nonzero = 0;
        for (const uint32_t o : old_) nonzero += o != 0 ? 1u : 0u;
        int64_t at_starts = 0;
        const uint32_t spans = noting_ ? walk_levels<true, true>(required.data(), counts.data(), &at_starts)
                                       : walk_levels<true, false>(required.data(), counts.data(), &at_starts);
        changed = static_cast<uint32_t>(static_cast<int64_t>(nonzero) + at_starts);
        return spans;
    }

private:
    [[nodiscard]] bool was_merged(std::size_t s, std::size_t e) const {
        if (s >= old_.size() || old_[s] != 1) return false;
        for (std::size_t i = s + 1; i < e; ++i)
            if (old_[i] != 0) return false;
        return true;
    }
    template <bool Zeroed>
    static void set_span(uint32_t* v, std::size_t s, std::size_t e) {
        v[s] = 1;
        if constexpr (!Zeroed)
            for (std::size_t i = s + 1; i < e; ++i) v[i] = 0;
    }
    // Level by level from the top (breadth first): the nodes still undecided at a level are a list (node index
    // times 2, plus 1 when an ancestor already set the required span), ascending; a node that does not take a
    // counts span puts its children on the next level's list. The same nodes as the depth-first walk, the same
    // decisions: a node's decision depends on its ancestors only, note() keeps minima and maxima (any order),
    // and the spans written by different nodes do not overlap. Levels at or above fail_level_ (ratio infinite:
    // descend, write nothing) are skipped: the walk starts with every node of the level below them.
    // Zeroed: `at_starts` gets, over the counts spans' first entries s, [old s == 0] - [old s == 1] (what the span's
    // 1 changes in the count of entries that differ from the old counts).
    template <bool Zeroed, bool Noting>
    uint32_t walk_levels(uint32_t* required, uint32_t* counts, int64_t* at_starts) const {
        const std::size_t levels = b_.levels;
        if (levels == 0 || fail_level_ == 0) return 0;  // no level decides a node: nothing is written
        const std::size_t top = std::min(levels - 1, fail_level_ - 1);
        Scratch& sc = scratch();
        const std::size_t cap = b_.level_width(0) + 1;
        if (sc.walk_a.size() < cap) sc.walk_a.resize(cap);
        if (sc.walk_b.size() < cap) sc.walk_b.resize(cap);
        uint32_t* cur = sc.walk_a.data();
        uint32_t* next = sc.walk_b.data();
        std::size_t count = b_.level_width(top);
        for (std::size_t j = 0; j < count; ++j) cur[j] = static_cast<uint32_t>(2 * j);
        uint32_t spans = 0;
        // note()'s four values in locals (registers) through the walk, stored back at the end.
        double above_one = above_one_, below_one = below_one_, above_scale = above_scale_, below_scale = below_scale_;
        for (std::size_t level = top;; --level) {
            std::size_t out = 0;
            const std::size_t child_width = level > 0 ? b_.level_width(level - 1) : 0;
            const bool decided_fit = static_cast<std::ptrdiff_t>(level) <= fit_level_;  // ratio 0: every node
            for (std::size_t i = 0; i < count; ++i) {
                const uint32_t item = cur[i];
                const std::size_t j = item >> 1;
                bool required_done = (item & 1u) != 0;
                const std::size_t s = first(level, j), e = last(level, j);
                double r = 0.0;
                if (!decided_fit) {
                    r = level_ratio(level, j);
                    if constexpr (Noting) note_into(r, new_scale_, above_one, below_one, above_scale, below_scale);
                }
                if (!required_done && r <= 1.0) {
                    set_span<Zeroed>(required, s, e);
                    required_done = true;
                }
                if (r <= new_scale_ || (r <= 1.0 && was_merged(s, e))) {
                    set_span<Zeroed>(counts, s, e);
                    spans += e - s > 1 ? 1u : 0u;
                    if constexpr (Zeroed) {
                        const uint32_t o = s < old_.size() ? old_[s] : 0u;
                        *at_starts += (o == 0 ? 1 : 0) - (o == 1 ? 1 : 0);
                    }
                    continue;
                }
                if (level == 0) continue;
                const uint32_t flag = required_done ? 1u : 0u;
                next[out] = static_cast<uint32_t>(4 * j) | flag;
                out += 1;
                next[out] = static_cast<uint32_t>(4 * j + 2) | flag;  // the right child, kept if it exists
                out += 2 * j + 1 < child_width ? 1 : 0;
            }
            if (level == 0 || out == 0) break;
            std::swap(cur, next);
            count = out;
        }
        above_one_ = above_one;
        below_one_ = below_one;
        above_scale_ = above_scale;
        below_scale_ = below_scale;
        return spans;
    }

    const LodBounds& b_;
    const LodView& view_;
    ViewTransform tf_;
    double c_, k_, k_cap_;
    double level_above_one_ = std::numeric_limits<double>::infinity(), level_below_one_ = 0.0;
    mutable uint64_t ready_ = 0;  // bit l: the ratios of level l are in ratios_
    std::vector<double>& ratios_ = scratch().ratios;  // per node, at level_start (root level first)
    // The noted ratios nearest 1 and new_scale_ from either side (0 or infinity: none).
    mutable double above_one_ = std::numeric_limits<double>::infinity(), below_one_ = 0.0;
    mutable double above_scale_ = std::numeric_limits<double>::infinity(), below_scale_ = 0.0;
    std::ptrdiff_t fit_level_ = -1;
    bool noting_ = true;
    std::size_t fail_level_ = std::numeric_limits<std::size_t>::max();
    bool closed_;
    bool inside_;
    bool coarse_offscreen_;
    double new_scale_;
    std::span<const uint32_t> old_;
    double sx_, sy_;
};

struct Limits {
    double eps;
    uint32_t max_rings, max_sides;
    double band;
    explicit Limits(const LodSettings& settings)
        : eps(tolerance_or_default(settings.tolerance_px)),
          max_rings(settings.max_rings_per_segment ? settings.max_rings_per_segment : default_max_rings),
          max_sides(std::max<uint32_t>(settings.max_sides ? settings.max_sides : default_max_sides, 3)),
          band(settings.hysteresis_band == 0.0 ? default_band : settings.hysteresis_band) {}
};

// Every segment's hull depth, off-axis factor and plane mask, into scratch(): z_min, k, outside.
// with_planes = false: the depths only (scratch().outside is left as it is).
void hull_depths(const Curve& curve, const LodView& view, double radius_m, bool with_planes = true) {
    const std::size_t n = curve.segment_count();
    Scratch& sc = scratch();
    sc.z_min.resize(n);
    sc.k.resize(n);
    if (with_planes) sc.outside.resize(n);
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius_m);
    HullConstants h{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) h.m[3 * c + r] = tf.rotation[c][r];
    for (int r = 0; r < 3; ++r) h.t[r] = tf.translation[r];
    h.near = view.near_m;
    h.far = view.far_m;
    h.tx = view.tan_half_x;
    h.ty = view.tan_half_y;
    h.neg_rx = -planes.rx;
    h.neg_ry = -planes.ry;
    h.neg_r = -planes.r;
    span_kernels().hull_depths(curve.segments.data(), n, h, sc.z_min.data(), sc.k.data(),
                               with_planes ? sc.outside.data() : nullptr);
}

// Per-segment pass: required Wang counts (and visibility, depth) of every segment from the hull depths and the
// bounds' cached Wang's M. Returns false if the wire is culled by the hull test.
bool per_segment_required(const Curve& curve, const LodView& view, const LodSettings& settings,
                          const Limits& lim, const LodBounds& bounds, double radius, WireLod& lod,
                          double& wire_z, double& wire_k) {
    const std::size_t n = curve.segment_count();
    hull_depths(curve, view, radius);
    Scratch& sc = scratch();
    const double* zmin = sc.z_min.data();
    const double* ks = sc.k.data();
    unsigned wire_outside = 63u;
    for (std::size_t i = 0; i < n; ++i) wire_outside &= sc.outside[i];
    if (wire_outside != 0) return false;

    lod.required.resize(n);
    wire_z = std::numeric_limits<double>::infinity();
    wire_k = 1.0;
    const double scale = lim.eps / view.focal_px;
    // Wang's M of every segment (cached in the bounds), then every segment's count and clamp flag in a lane kernel
    // (computed for all; used where the segment needs them).
    const double* mm = &bounds.data[bounds.data.size() - bounds.segments];  // wang_m(0 .. n): segments == n here
    sc.raw.resize(n);
    sc.clamped.resize(n);
    span_kernels().wang_counts(zmin, ks, mm, n, scale, static_cast<double>(lim.max_rings), sc.raw.data(),
                               sc.clamped.data());
    uint32_t visible = 0, clamped = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const bool seg_visible = sc.outside[i] == 0;
        uint32_t raw = 1;
        if (seg_visible || !settings.coarse_offscreen_segments) {
            raw = static_cast<uint32_t>(sc.raw[i]);  // an integer in [1, max_rings]
            clamped += sc.clamped[i] != 0.0 ? 1u : 0u;
            if (seg_visible) {
                ++visible;
                wire_z = std::min(wire_z, zmin[i]);
                wire_k = std::max(wire_k, ks[i]);
            }
        }
        lod.required[i] = raw;
    }
    lod.visible_segments += visible;
    lod.clamped_segments += clamped;
    return true;
}

bool same_settings(const WireLod::Coherence& c, const Limits& lim, const LodSettings& s) {
    return c.tolerance_px == lim.eps && c.band == lim.band && c.max_sides == lim.max_sides &&
           c.max_rings == lim.max_rings && c.coarse_offscreen == s.coarse_offscreen_segments &&
           c.keep_node_resolution == s.keep_node_resolution;
}

// The coherence test (WireLod::Coherence): true if the state of the last update stands for this camera.
bool reuse(const Curve& curve, const LodView& view, const LodSettings& settings, const Limits& lim,
           const LodBounds& bounds, WireLod& lod) {
    const WireLod::Coherence& c = lod.coherence;
    if (!c.valid || c.bounds != &bounds || c.bounds_version != bounds.version || !lod.visible ||
        lod.counts.size() != curve.segment_count() || !same_settings(c, lim, settings)) {
        return false;
    }
    const SphereScreenBound sb = sphere_screen_bound(bounds.sphere.centre_m, bounds.sphere.radius_m, view, lim.eps);
    if (!sb.inside) return false;
    if (!c.exact_sides &&
        sides_for_radius(bounds.radius_max_m, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) != 3) {
        return false;
    }
    if (!c.whole && !one_ring_per_segment(bounds, sb)) return false;
    // Every point of the sphere moved by at most delta in view space: |R' - R| |p - e'| + |e' - e|.
    const ViewTransform tf(view);
    double rf = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double d = tf.rotation[i][j] - c.rotation[i][j];
            rf += d * d;
        }
    const double delta = std::sqrt(rf) * (glm::length(bounds.sphere.centre_m - view.eye_m) + bounds.sphere.radius_m) +
                         glm::length(view.eye_m - c.eye_m);
    if (!(c.z_lo_m - delta > view.near_m)) return false;
    const double kr = sb.k / c.k;
    const double factor = std::max(kr * c.z_lo_m / (c.z_lo_m - delta), (c.z_lo_m + delta) / (c.z_lo_m * kr));
    if (!(factor * (1.0 + 1e-9) < c.margin)) return false;
    double z_min = sb.z_lo_m;
    if (c.exact_sides) {
        // The segments' nearest depth moved by at most delta, their off-axis factors as a = |x|/z allows:
        // sqrt(k^2 - 1) within (sqrt(k^2 - 1) -+ sqrt2 e) / (1 +- e), e = delta / z. The side count must not move.
        const double e = delta / c.wire_z_m;
        if (!(e < 0.5) || !(c.wire_z_m - delta > view.near_m)) return false;
        const double ka = std::sqrt(std::max(c.wire_k * c.wire_k - 1.0, 0.0));
        const double ka_hi = (ka + std::numbers::sqrt2 * e) / (1.0 - e);
        const double ka_lo = std::max(0.0, (ka - std::numbers::sqrt2 * e) / (1.0 + e));
        const double r = bounds.radius_max_m;
        const uint32_t most =
            sides_for_radius(r, c.wire_z_m - delta, std::sqrt(1.0 + ka_hi * ka_hi), view, lim.eps, lim.max_sides);
        const uint32_t least =
            sides_for_radius(r, c.wire_z_m + delta, std::sqrt(1.0 + ka_lo * ka_lo), view, lim.eps, lim.max_sides);
        if (most != lod.required_sides || least != lod.required_sides) return false;
        z_min = c.wire_z_m - delta;  // a lower bound of the segments' nearest depth
    }
    lod.z_min_m = z_min;
    lod.changed_counts = 0;
    ++lod.reused;
    return true;
}

// Wang's count of one segment from its hull depth, with the cached M (wang_ring_count() on it).
uint32_t wang_cached(double m, double eps_world, const Limits& lim, uint32_t& clamped) {
    if (!(eps_world > 0.0) || !std::isfinite(m)) return lim.max_rings;
    const double c = std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world)));
    const uint32_t raw = !(c < static_cast<double>(lim.max_rings)) ? lim.max_rings
                                                                     : std::max<uint32_t>(1, static_cast<uint32_t>(c));
    if (raw >= lim.max_rings && !(c <= static_cast<double>(lim.max_rings))) ++clamped;
    return raw;
}

enum class SegmentPass { done, culled, fallback };

// The per-segment pass of a wire partly out of view whose side count the wire's sphere already fixes at 3:
// each segment's sphere (LodBounds level 0) decides it when it lies inside the frustum (visible; one ring when
// the sphere's depth allows) or outside a plane (off screen, so is its hull); only the other segments take the
// hull test and hull depth. The same required counts and visibility as per_segment_required(); the depth kept
// is a lower bound. `fallback` when no segment was found visible (the hull test must then decide culling).
SegmentPass per_segment_bounded(const Curve& curve, const LodView& view, const Limits& lim, const LodBounds& b,
                                double radius, WireLod& lod, double& wire_z) {
    const std::size_t n = curve.segment_count();
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius);
    const double tx = view.tan_half_x, ty = view.tan_half_y;
    const double sx = edge_factors(view).sx, sy = edge_factors(view).sy;
    const double scale = lim.eps / view.focal_px;
    lod.required.resize(n);
    unsigned wire_outside = 63u;
    wire_z = std::numeric_limits<double>::infinity();
    uint32_t visible = 0, clamped = 0;
    const double* d0 = b.level_data(0);  // level 0: centre x, y, z and radius of each segment's sphere
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 q = tf(glm::dvec3(d0[i], d0[n + i], d0[2 * n + i]));
        const double r0 = d0[3 * n + i], ri = r0 + radius;
        const double l = q.x + q.z * tx, rt = q.z * tx - q.x, bt = q.y + q.z * ty, tp = q.z * ty - q.y;
        const double ne = q.z - view.near_m, fa = view.far_m - q.z;
        const double rx = ri * sx, ry = ri * sy;
        const unsigned outside = (l < -rx ? 1u : 0u) | (rt < -rx ? 2u : 0u) | (bt < -ry ? 4u : 0u) |
                                 (tp < -ry ? 8u : 0u) | (ne < -ri ? 16u : 0u) | (fa < -ri ? 32u : 0u);
        if (outside != 0) {  // every control point is outside these planes: the hull test says off screen too
            wire_outside &= outside;
            lod.required[i] = 1;
            continue;
        }
        const bool inside = l >= rx && rt >= rx && bt >= ry && tp >= ry && ne >= ri && fa >= ri;
        if (inside) {
            const double zl = q.z - r0;  // > near: the sphere is in front of the near plane
            const double a = std::min(tx, (std::abs(q.x) + r0) / zl), c = std::min(ty, (std::abs(q.y) + r0) / zl);
            const double k = std::sqrt(1.0 + a * a + c * c);
            wire_outside = 0;
            ++visible;
            if (3.0 * b.wang_m(i) <= 4.0 * (scale * zl / k) * (1.0 - 1e-9)) {
                lod.required[i] = 1;  // the hull's depth is larger and its k smaller: the exact count is 1 too
                wire_z = std::min(wire_z, zl);
                continue;
            }
            const HullDepth h = hull_depth(tf.hull(curve.segments[i]), view);
            lod.required[i] = wang_cached(b.wang_m(i), scale * h.z_min / h.k, lim, clamped);
            wire_z = std::min(wire_z, h.z_min);
            continue;
        }
        const ViewHull hull = tf.hull(curve.segments[i]);
        const unsigned o = planes.outside(hull);
        wire_outside &= o;
        if (o != 0) {
            lod.required[i] = 1;
            continue;
        }
        ++visible;
        const HullDepth h = hull_depth(hull, view);
        lod.required[i] = wang_cached(b.wang_m(i), scale * h.z_min / h.k, lim, clamped);
        wire_z = std::min(wire_z, h.z_min);
    }
    if (wire_outside != 0) return SegmentPass::culled;  // a superset of the hull test's planes: culled as well
    if (visible == 0) return SegmentPass::fallback;
    lod.visible_segments = visible;
    lod.clamped_segments = clamped;
    return SegmentPass::done;
}

// built_levels: the hierarchy levels of `bounds` that were built (all but for update_lod_once(), which leaves out
// levels an update of a wire inside the frustum cannot read: see TopLevels).
bool update_lod_impl(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                     const LodBounds& bounds, bool sphere_cull, bool use_bound,
                     std::size_t built_levels = std::numeric_limits<std::size_t>::max(),
                     const SphereScreenBound* known_sb = nullptr) {
    const std::size_t n = curve.segment_count();
    if (sphere_cull && sphere_outside_view(bounds.sphere, view)) return cull_lod(lod);
    if (n == 0) {
        return cull_lod(lod);
    }
    const Limits lim(settings);
    const double radius = bounds.radius_max_m;
    const bool merge = !settings.keep_node_resolution && bounds.segments == n && bounds.levels > 0;
    if (use_bound && reuse(curve, view, settings, lim, bounds, lod)) return false;
    lod.coherence.valid = false;

    Scratch& sc = scratch();
    sc.old_counts.assign(lod.counts.begin(), lod.counts.end());
    const bool restart = sc.old_counts.size() != n;
    if (restart) sc.old_counts.assign(n, 0);
    const std::span<const uint32_t> old(sc.old_counts);

    lod.clamped_segments = 0;
    lod.changed_counts = 0;
    lod.visible_segments = 0;
    lod.spans = 0;
    lod.bounded = false;

    // The per-wire bound (sphere of the whole wire), also the spans' off-axis factor (every span lies
    // inside).
    SphereScreenBound sb;
    if (bounds.sphere.radius_m >= 0.0) {
        sb = known_sb != nullptr ? *known_sb
                                 : sphere_screen_bound(bounds.sphere.centre_m, bounds.sphere.radius_m, view, lim.eps);
    } else {
        sb.k = edge_factors(view).corner;
    }
    SpanMerger merger(bounds, view, lim.eps, sb.inside, sb.k, curve.closed,
                      settings.coarse_offscreen_segments, lim.band < 0.0 ? 1.0 : 1.0 / (1.0 + lim.band), old);
    // The margin only serves a Coherence, which is kept for bounds that outlive this update and a wire inside.
    const bool keeps_coherence = use_bound && !bounds.transient && sb.inside;
    if (!keeps_coherence) merger.skip_margin();
    merger.set_depth_range(sb.z_lo_m, sb.z_hi_m, built_levels);
    // Every segment lies in a span of both kinds (the common case on screen): the walk below writes each span's
    // first entry over zeros (the zeroed walk), so nothing before it needs to fill the counts.
    const bool zeroed_walk = merge && merger.writes_every_segment();

    // A sphere inside the frustum whose conservative side count is 3 (so the exact one is too) is decided
    // here.
    bool decided = false, whole = false, conservative_sides = false;
    double wire_z = std::numeric_limits<double>::infinity();
    double wire_k = 1.0;
    if (use_bound && bounds.sphere.radius_m >= 0.0 && sb.inside) {
        const std::size_t root = merger.root_level();
        // A root not built has a ratio above 1 (TopLevels): not one interval.
        const double root_ratio = !merge                  ? 0.0
                                  : root < built_levels ? merger.ratio(root, 0)
                                                        : std::numeric_limits<double>::infinity();
        if (merge) merger.note(root_ratio);
        if (merge && root_ratio <= merger.counts_scale(root, 0)) {
            // The whole wire is one interval for the counts (hysteresis threshold), so for the tolerance too.
            lod.required.assign(n, 0);
            lod.required[0] = 1;
            lod.counts.assign(n, 0);
            lod.counts[0] = 1;
            lod.spans = n > 1 ? 1u : 0u;
            decided = true;
            whole = true;
        } else if (one_ring_per_segment(bounds, sb)) {
            if (!zeroed_walk) lod.required.assign(n, 1);  // one ring each (the zeroed walk writes them itself)
            decided = true;
        }
        if (decided) {
            lod.bounded = true;
            lod.visible_segments = static_cast<uint32_t>(n);  // the sphere is inside the frustum
            if (sides_for_radius(radius, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) == 3) {
                wire_z = sb.z_lo_m;  // the conservative side count is the least: so is the exact one
                wire_k = sb.k;
                conservative_sides = true;
            } else {
                hull_depths(curve, view, radius, false);  // the exact side count needs the segments' depths
                const Scratch& d = scratch();
                for (std::size_t i = 0; i < n; ++i) {
                    wire_z = std::min(wire_z, d.z_min[i]);
                    wire_k = std::max(wire_k, d.k[i]);
                }
            }
        }
    }
    if (!decided && use_bound && bounds.sphere.radius_m >= 0.0 && !sb.inside && settings.coarse_offscreen_segments &&
        sides_for_radius(radius, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) == 3) {
        const SegmentPass pass = per_segment_bounded(curve, view, lim, bounds, radius, lod, wire_z);
        if (pass == SegmentPass::culled) {
            return cull_lod(lod);
        }
        if (pass == SegmentPass::done) {
            decided = true;
            lod.bounded = true;
            wire_z = std::max(wire_z, sb.z_lo_m);
            wire_k = sb.k;  // with wire_z >= the sphere's z_lo: the side count is 3, as the exact one
        } else {
            lod.visible_segments = 0;
            lod.clamped_segments = 0;
        }
    }
    if (!decided && !per_segment_required(curve, view, settings, lim, bounds, radius, lod, wire_z, wire_k)) {
        return cull_lod(lod);
    }

    lod.visible = true;
    bool zeroed = false;
    uint32_t zeroed_changed = 0;
    if (!whole && zeroed_walk) {
        // The per-segment counts (and the hysteresis on them) are never read.
        lod.required.assign(n, 0);
        lod.counts.assign(n, 0);
        lod.spans = merger.apply_zeroed(lod.required, lod.counts, zeroed_changed);
        zeroed = true;
    } else if (!whole) {
        // Per-segment hysteresis on the Wang counts (all >= 1), then the spans over both.
        lod.counts.resize(n);
        const uint32_t* req = lod.required.data();
        uint32_t* cnt = lod.counts.data();
        for (std::size_t i = 0; i < n; ++i) {
            // Hysteresis keeps an old count, but never above the cap in force now (it may have been lowered).
            // hysteresis_count() is the new count unless the old one is larger: that test alone in the loop.
            const uint32_t o = old[i], r = req[i];
            cnt[i] = std::min(o > r ? hysteresis_count(o, r, lim.band) : r, lim.max_rings);
        }
        if (merge) lod.spans = merger.apply(lod.required, lod.counts);
    }
    bool changed = restart;
    if (zeroed) {
        lod.changed_counts += zeroed_changed;
    } else {
        uint32_t changed_counts = 0;  // a local sum (not the member): the loop vectorizes
        const uint32_t* cnt = lod.counts.data();
        for (std::size_t i = 0; i < n; ++i) changed_counts += cnt[i] != old[i] ? 1u : 0u;
        lod.changed_counts += changed_counts;
    }
    changed = changed || lod.changed_counts != 0;

    if (lod.visible_segments == 0) {
        // The wire's hull meets the frustum but no single segment's does (the wire wraps around the view):
        // draw it coarsely with the fewest sides; nothing of it is on screen.
        wire_z = std::numeric_limits<double>::infinity();
    }
    lod.z_min_m = std::isfinite(wire_z) ? wire_z : 0.0;
    // conservative_sides: the bound's call above, with these very arguments (the visible segments are all of
    // them), gave 3 (and so does the non-finite case).
    lod.required_sides = conservative_sides       ? 3u
                         : std::isfinite(wire_z) ? sides_for_radius(radius, wire_z, wire_k, view, lim.eps, lim.max_sides)
                                                 : 3u;
    // Clamped before the comparison: a lowered max_sides changes the sides, and the caller must hear of it.
    const uint32_t sides = std::min(
        restart ? lod.required_sides : hysteresis_count(lod.sides, lod.required_sides, lim.band), lim.max_sides);
    changed = changed || sides != lod.sides;
    lod.sides = sides;
    lod.radius_px = std::isfinite(wire_z) ? radius * view.focal_px * wire_k / std::max(wire_z, view.near_m) : 0.0;
    lod.drawn_sides = drawn_sides_for(lod.radius_px, lod.sides, lod.drawn_sides, settings, lim.band);
    if (keeps_coherence && lod.bounded && merger.margin() > 1.0) {
        WireLod::Coherence& c = lod.coherence;
        c.valid = true;
        c.bounds = &bounds;
        c.bounds_version = bounds.version;
        c.eye_m = view.eye_m;
        c.rotation = ViewTransform(view).rotation;
        c.z_lo_m = sb.z_lo_m;
        c.k = sb.k;
        c.whole = whole;
        c.exact_sides = !conservative_sides;
        c.wire_z_m = wire_z;
        c.wire_k = wire_k;
        c.margin = merger.margin();
        c.tolerance_px = lim.eps;
        c.band = lim.band;
        c.max_sides = lim.max_sides;
        c.max_rings = lim.max_rings;
        c.coarse_offscreen = settings.coarse_offscreen_segments;
        c.keep_node_resolution = settings.keep_node_resolution;
    }
    return changed;
}

}  // namespace

namespace {

// Working memory of compute_lod_bounds (one per thread, grows once): the level-0 boxes and the chord end points of
// the nodes of two adjacent levels (structure of arrays).
struct BoundsScratch {
    std::vector<double> boxes;    // 6 n: lo x, y, z, hi x, y, z of every segment
    std::vector<double> ends[2];  // 6 arrays of a level's width: first point x, y, z, last point x, y, z
};
BoundsScratch& bounds_scratch() {
    thread_local BoundsScratch s;
    return s;
}

// std::min (std::max) of init and v[0..n) in sequence, which keeps the first of equal values: in four lanes,
// exact unless the result is a zero (the one value with two encodings, -0 and +0: then in sequence).
template <bool Max>
double ordered_extreme(const double* v, std::size_t n, double init) {
    auto pick = [](double acc, double x) { return Max ? max_of(acc, x) : min_of(acc, x); };
    double acc[4] = {init, init, init, init};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) acc[k] = pick(acc[k], v[i + k]);
    for (; i < n; ++i) acc[0] = pick(acc[0], v[i]);
    const double r = pick(pick(acc[0], acc[1]), pick(acc[2], acc[3]));
    if (r != 0.0) return r;
    double seq = init;
    for (i = 0; i < n; ++i) seq = pick(seq, v[i]);
    return seq;
}
double ordered_min(const double* v, std::size_t n) {
    return ordered_extreme<false>(v, n, std::numeric_limits<double>::infinity());
}
double ordered_max(const double* v, std::size_t n) {
    return ordered_extreme<true>(v, n, -std::numeric_limits<double>::infinity());
}

// std::max(0.0, r) over the radii in sequence (curve_bounding_sphere()'s radius): four lanes, in sequence when
// the result is a zero.
double largest_radius(const std::vector<float>& radii) {
    const std::size_t n = radii.size();
    double acc[4] = {0.0, 0.0, 0.0, 0.0};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) acc[k] = max_of(acc[k], static_cast<double>(radii[i + k]));
    for (; i < n; ++i) acc[0] = max_of(acc[0], static_cast<double>(radii[i]));
    const double r = max_of(max_of(acc[0], acc[1]), max_of(acc[2], acc[3]));
    if (r != 0.0) return r;
    double seq = 0.0;
    for (const float x : radii) seq = std::max(seq, static_cast<double>(x));
    return seq;
}

}  // namespace

BoundingSphere curve_bounding_sphere(const Curve& curve) {
    // The box of all control points: std::min / std::max (glm::min / glm::max) over b0, b1, b2, b3 of every
    // segment in sequence from +inf (-inf), here as 12 lanes (wire_box), a zero redone in sequence; the radius
    // std::max(0.0, r) over the radii in sequence. compute_lod_bounds() gets the same sphere from its boxes.
    const std::size_t n = curve.segments.size();
    if (n == 0) return {};
    double lo12[12], hi12[12];
    span_kernels().box(curve.segments.data(), n, lo12, hi12);
    glm::dvec3 lo(0.0), hi(0.0);
    for (int c = 0; c < 3; ++c) {
        double l = min_of(min_of(lo12[c], lo12[c + 3]), min_of(lo12[c + 6], lo12[c + 9]));
        double h = max_of(max_of(hi12[c], hi12[c + 3]), max_of(hi12[c + 6], hi12[c + 9]));
        if (l == 0.0 || h == 0.0) {
            double sl = std::numeric_limits<double>::infinity(), sh = -std::numeric_limits<double>::infinity();
            for (const CubicBezier& s : curve.segments)
                for (const glm::dvec3* q : {&s.b0, &s.b1, &s.b2, &s.b3}) {
                    sl = min_of(sl, (*q)[c]);
                    sh = max_of(sh, (*q)[c]);
                }
            l = sl;
            h = sh;
        }
        lo[c] = l;
        hi[c] = h;
    }
    const double radius = largest_radius(curve.radius_m);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    // Round the radius up by a relative hair so rounding in the centre cannot leave a corner outside.
    return {centre, (0.5 * glm::length(hi - lo)) * (1.0 + 1e-12) + radius, radius};
}

namespace {

// The levels an update of a wire inside the frustum reads (update_lod_once()). With deviations that never
// decrease from a level to the one above, a level l whose smallest deviation fails at the far depth of the wire's
// sphere, (dev_min(l) c) k > z_hi (c = focal / eps, k the sphere's off-axis bound: set_depth_range()'s test), makes
// every level above it fail too and none fit (their largest deviation is at least that, and the fit test's
// denominator new_scale z_lo is at most z_hi), so set_depth_range() reads nothing above l and the walk starts below
// it. The root (the one other node the update reads) has a ratio above 1: its deviation is >= dev_min(l), and
// its sphere's nearest depth is at most the depth of the wire's first control point, which lies in both spheres,
// so at most z_hi, up to roundings far below `slack`; the update takes it as not one interval, which it is not.
// Deviations never decrease when no value overflows and none is NaN (a parent's is the larger child's plus a
// square root, rounded up or equal): the coordinates are finite, below 1e149 in magnitude (then no square or sum
// of squares of the kernels overflows), which the sphere's box shows for all but NaN ones and level 0's probe
// (NaN then) for those.
struct TopLevels {
    double c, k, above;  // stop after level l when (dev_min(l) c) k > above (= z_hi + slack)
};

// Returns the number of levels built: all, or with `stop` (when level 0's probe shows every coordinate finite)
// up to the first that TopLevels lets stop after; that level below the root has its deviations (and their range)
// but no spheres, which the update does not read (the walk starts below it).
std::size_t compute_lod_bounds_impl(const Curve& curve, LodBounds& out, const BoundingSphere* known_sphere,
                                    const TopLevels* stop = nullptr) {
    const std::size_t n = curve.segment_count();
    out.segments = n;
    out.sphere = BoundingSphere{};  // curve_bounding_sphere(curve), from the level-0 boxes below
    // largest_radius() of the same curve, as the given sphere keeps it (or again).
    out.radius_max_m = known_sphere != nullptr && known_sphere->tube_radius_m >= 0.0 ? known_sphere->tube_radius_m
                                                                                  : largest_radius(curve.radius_m);
    out.wang_m_max = 0.0;
    out.levels = 0;
    // Unique over all curves (a state made for other bounds never matches): each thread takes blocks of 2^16
    // versions from one counter, so threads do not contend for it on every wire.
    static std::atomic<uint64_t> version_blocks{0};
    thread_local uint64_t next_version = 0, block_end = 0;
    if (next_version == block_end) {
        const uint64_t block = version_blocks.fetch_add(1, std::memory_order_relaxed);
        next_version = (block << 16) + 1;  // never 0
        block_end = (block + 1) << 16;
    }
    out.version = next_version++;
    if (n == 0) {
        out.data.clear();
        return 0;
    }
    // Level widths and where each level starts (root first).
    uint32_t levels = 1;
    while (out.level_width(levels - 1) > 1) ++levels;
    out.levels = levels;
    std::size_t nodes = 0;
    for (std::size_t l = levels; l-- > 0;) {
        out.level_start[l] = static_cast<uint32_t>(nodes);
        nodes += out.level_width(l);
    }
    // Every entry is written below: a buffer of the right size (the same wire next frame, or a per-thread one for
    // wires of equal length) is not cleared first.
    if (out.data.size() != 2 * levels + 5 * nodes + n) out.data.assign(2 * levels + 5 * nodes + n, 0.0);
    double* wang = out.data.data() + 2 * levels + 5 * nodes;
    BoundsScratch& sc = bounds_scratch();
    if (sc.ends[0].size() < 6 * n) {
        sc.ends[0].resize(6 * n);
        sc.ends[1].resize(6 * n);
    }
    // The level-0 boxes only where the wire's box is not known already (as its sphere).
    if (known_sphere == nullptr && sc.boxes.size() < 6 * n) sc.boxes.resize(6 * n);
    const SpanKernels& kernels = span_kernels();
    // Level 0 with its deviation range (out.data[0], [1]) and the largest M (never -0: a root of a sum of squares).
    double range0[4];
    double* boxes = known_sphere == nullptr ? sc.boxes.data() : nullptr;
    kernels.level0(curve.segments.data(), n, out.level_data(0), wang, boxes, sc.ends[0].data(), range0);
    out.data[0] = range0[0];
    out.data[1] = range0[1];
    out.wang_m_max = range0[2];
    if (stop != nullptr && !std::isfinite(range0[3])) stop = nullptr;  // a coordinate NaN (or an overflow)
    if (known_sphere != nullptr) {
        out.sphere = *known_sphere;
    } else {
        // The wire's box.
        const double* b = sc.boxes.data();
        const glm::dvec3 lo(ordered_min(b, n), ordered_min(b + n, n), ordered_min(b + 2 * n, n));
        const glm::dvec3 hi(ordered_max(b + 3 * n, n), ordered_max(b + 4 * n, n), ordered_max(b + 5 * n, n));
        // curve_bounding_sphere(curve): the same box (the same minima and maxima), the same rounding.
        const double radius = out.radius_max_m;
        out.sphere = {0.5 * (lo + hi), (0.5 * glm::length(hi - lo)) * (1.0 + 1e-12) + radius, radius};
    }
    // Levels 1 and up, each from the one below, with their deviation ranges; the chord ends alternate between two
    // buffers.
    // With a stop test, a level's deviations come first: a level that stops the build needs no spheres.
    if (stop != nullptr && (out.level_deviation_min(0) * stop->c) * stop->k > stop->above) return 1;
    for (std::size_t level = 1; level < levels; ++level) {
        const double* child = out.level_data(level - 1);
        const std::size_t cw = out.level_width(level - 1), w = out.level_width(level);
        double* parent = out.level_data(level);
        const double* e = sc.ends[(level - 1) & 1].data();
        double* f = sc.ends[level & 1].data();
        if (stop == nullptr || level + 1 == levels) {  // the root: nothing above it to leave out
            kernels.merge_level(child, e, cw, parent, f, w, out.data.data() + 2 * level);
            continue;
        }
        kernels.merge_deviations(child, e, cw, parent, f, w, out.data.data() + 2 * level);
        if ((out.level_deviation_min(level) * stop->c) * stop->k > stop->above) return level + 1;
        kernels.merge_spheres(child, cw, parent, w);
    }
    return levels;
}

}  // namespace

void compute_lod_bounds(const Curve& curve, LodBounds& out) { compute_lod_bounds_impl(curve, out, nullptr); }

void compute_lod_bounds(const Curve& curve, LodBounds& out, const BoundingSphere& sphere) {
    compute_lod_bounds_impl(curve, out, &sphere);
}

SphereScreenBound sphere_screen_bound(const glm::dvec3& centre_m, double radius_m, const LodView& view,
                                      double tolerance_px) {
    SphereScreenBound b;
    const ViewTransform tf(view);
    const glm::dvec3 q = tf(centre_m);
    const PlaneTest out(view, radius_m);
    b.outside = out.outside(q);
    const double r = radius_m;
    b.inside = q.x + q.z * out.tx >= out.rx && q.z * out.tx - q.x >= out.rx && q.y + q.z * out.ty >= out.ry &&
               q.z * out.ty - q.y >= out.ry && q.z - view.near_m >= r && view.far_m - q.z >= r;
    b.z_lo_m = std::max(q.z - r, view.near_m);
    b.z_hi_m = q.z + r;
    double a = view.tan_half_x, c = view.tan_half_y;
    if (q.z - r > 0.0) {
        a = std::min(a, (std::abs(q.x) + r) / (q.z - r));
        c = std::min(c, (std::abs(q.y) + r) / (q.z - r));
    }
    b.k = std::sqrt(1.0 + a * a + c * c);
    b.eps_world_m = tolerance_or_default(tolerance_px) * b.z_lo_m / (view.focal_px * b.k);
    return b;
}

bool sphere_outside_view(const BoundingSphere& sphere, const LodView& view) {
    if (!(sphere.radius_m >= 0.0)) return false;
    const ViewTransform tf(view);
    // The centre and the hull's control points each reach view space with a rounding error of a few ulps of
    // |point| + |eye|; far from the origin (5e11 m: ~1e-4 m) that exceeds the sphere's own slack and the
    // sphere could cull a wire the hull test keeps. Inflate the sphere by a bound of both errors.
    const double rounding =
        64.0 * std::numeric_limits<double>::epsilon() * (glm::length(sphere.centre_m) + glm::length(view.eye_m));
    return PlaneTest(view, sphere.radius_m + rounding).outside(tf(sphere.centre_m)) != 0;
}

bool cull_lod(WireLod& lod) {
    bool changed = false;
    mark_culled(lod, changed);
    return changed;
}

bool one_ring_per_segment(const LodBounds& bounds, const SphereScreenBound& b) {
    // Wang: ceil(sqrt(3M / (4 eps))) == 1 iff 3M <= 4 eps; the margin covers the rounding of eps_world
    // between the bound and the per-segment evaluation (which uses a larger eps_world anyway).
    return std::isfinite(bounds.wang_m_max) && 3.0 * bounds.wang_m_max <= 4.0 * b.eps_world_m * (1.0 - 1e-9);
}

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const BoundingSphere* bounds) {
    thread_local LodBounds lb;
    if (bounds != nullptr) {
        compute_lod_bounds(curve, lb, *bounds);  // the caller's sphere, not the boxes' again
    } else {
        compute_lod_bounds(curve, lb);
    }
    return update_lod_impl(curve, view, settings, lod, lb, bounds != nullptr && bounds->radius_m >= 0.0,
                           false);
}

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const LodBounds& bounds) {
    if (bounds.segments != curve.segment_count()) {
        return update_lod(curve, view, settings, lod, static_cast<const BoundingSphere*>(nullptr));
    }
    return update_lod_impl(curve, view, settings, lod, bounds, true, true);
}

bool update_lod_once(const Curve& curve, const BoundingSphere& sphere, const LodView& view,
                     const LodSettings& settings, WireLod& lod) {
    thread_local LodBounds bounds;
    bounds.transient = true;  // no Coherence: the next update has new bounds
    // The stop of TopLevels where its conditions hold: a merging wire whose sphere is inside the frustum, finite
    // and bounded coordinates (the sphere's box here, level 0's probe for NaN), a positive finite z_hi.
    const double eps = tolerance_or_default(settings.tolerance_px);
    const SphereScreenBound sb = sphere.radius_m >= 0.0 ? sphere_screen_bound(sphere.centre_m, sphere.radius_m, view, eps)
                                                        : SphereScreenBound{};
    const double zh = std::max(sb.z_hi_m, view.near_m);
    const double extent = (std::abs(sphere.centre_m.x) + std::abs(sphere.centre_m.y) + std::abs(sphere.centre_m.z)) +
                          sphere.radius_m;
    const double eye = (std::abs(view.eye_m.x) + std::abs(view.eye_m.y)) + std::abs(view.eye_m.z);
    const TopLevels stop{view.focal_px / eps, sb.k, zh + 1e-6 * ((zh + extent) + eye)};
    const bool may_stop = sb.inside && !settings.keep_node_resolution && extent <= 1e149 && eye <= 1e149 &&
                          zh > 0.0 && zh <= 1e149 && std::isfinite(stop.c * stop.k);
    const std::size_t built = compute_lod_bounds_impl(curve, bounds, &sphere, may_stop ? &stop : nullptr);
    return update_lod_impl(curve, view, settings, lod, bounds, false, true, built, &sb);
}

ScreenError measure_screen_error(const Curve& curve, std::span<const RingParam> params, const LodView& view,
                                 int samples_per_segment) {
    ScreenError out;
    const std::size_t n_seg = curve.segment_count();
    const std::size_t n_rings = params.size();
    if (n_seg == 0 || n_rings == 0 || samples_per_segment < 1) return out;

    std::vector<glm::dvec3> centre(n_rings);
    for (std::size_t k = 0; k < n_rings; ++k) {
        centre[k] = view.to_view(position(curve.segments[params[k].segment], params[k].t));
    }
    // First ring of every segment (rings are in segment order).
    std::vector<std::size_t> first(n_seg + 1, n_rings);
    for (std::size_t k = n_rings; k-- > 0;) first[params[k].segment] = k;
    for (std::size_t i = n_seg; i-- > 0;) first[i] = std::min(first[i], first[i + 1]);

    const std::size_t n_pieces = curve.closed ? n_rings : n_rings - 1;
    auto piece_distance = [&](const glm::dvec2& p, std::ptrdiff_t j) {
        if (curve.closed) {
            j = (j % static_cast<std::ptrdiff_t>(n_pieces) + static_cast<std::ptrdiff_t>(n_pieces)) %
                static_cast<std::ptrdiff_t>(n_pieces);
        } else if (j < 0 || j >= static_cast<std::ptrdiff_t>(n_pieces)) {
            return std::numeric_limits<double>::infinity();
        }
        const std::size_t a = static_cast<std::size_t>(j);
        const std::size_t b = (a + 1) % n_rings;
        return distance_to_view_piece(p, centre[a], centre[b], view);
    };

    for (std::size_t i = 0; i < n_seg; ++i) {
        const std::size_t lo = first[i];
        const std::size_t hi = first[i + 1];  // one past the segment's last ring
        for (int s = 0; s <= samples_per_segment; ++s) {
            const double t = static_cast<double>(s) / samples_per_segment;
            const glm::dvec3 q = view.to_view(position(curve.segments[i], t));
            if (!(q.z >= view.near_m && q.z <= view.far_m)) continue;
            const glm::dvec2 p = view.view_to_px(q);
            if (!(p.x >= 0.0 && p.x <= view.width_px && p.y >= 0.0 && p.y <= view.height_px)) continue;
            // The piece that holds t: the last ring of this segment with param t <= t.
            std::ptrdiff_t k = static_cast<std::ptrdiff_t>(lo);
            while (static_cast<std::size_t>(k + 1) < hi && params[static_cast<std::size_t>(k + 1)].t <= t) ++k;
            if (lo == hi) k = static_cast<std::ptrdiff_t>(lo) - 1;  // no ring on this segment (count 0): neighbours
            const double d = std::min({piece_distance(p, k - 1), piece_distance(p, k), piece_distance(p, k + 1)});
            ++out.samples;
            if (d > out.max_px) {
                out.max_px = d;
                out.worst_segment = static_cast<uint32_t>(i);
                out.worst_t = t;
            }
        }
    }
    return out;
}

}  // namespace wire
