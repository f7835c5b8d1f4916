// Internal: the span hierarchy's lane kernels (span_kernels.inl) at the widest width the CPU has, and what they
// read of the view.
#pragma once

#include "wire/curve.hpp"

#include <cstddef>

namespace wire::lod_stage {

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
SpanKernels choose_span_kernels();
inline const SpanKernels& span_kernels() {
    static const SpanKernels kernels = choose_span_kernels();
    return kernels;
}

}  // namespace wire::lod_stage
