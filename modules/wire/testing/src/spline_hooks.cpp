// The curve stage's test hooks (wire/testing/spline_hooks.hpp): its internal kernels as the tests call them.
#include "wire/testing/spline_hooks.hpp"

#include "spline/kernels.hpp"
#include "spline/scratch.hpp"
#include "spline/tension.hpp"

#include <algorithm>

namespace wire {

using namespace curve_stage;

namespace detail {

std::size_t spread_test(std::size_t count, const double* len, const double* kx, const double* ky, const double* kz,
                        const double* ax, const double* ay, const double* az, const double* ec, const double* eq,
                        double* lk, double* sum, double* miss2, double* flag, bool certified) {
    in_whole_blocks(count, [&](std::size_t o, std::size_t c) {  // as concentrated_turns runs it
        spread_kernel(c, len + o, kx + o, ky + o, kz + o, ax + o, ay + o, az + o, ec + o, eq + o, lk + o, sum + o,
                      miss2 + o, flag + o);
    });
    const std::size_t uncertain = static_cast<std::size_t>(std::count(flag, flag + count, 1.0));
    if (certified) {
        decide_flagged(count, lk, sum, miss2, flag);
        return uncertain;
    }
    for (std::size_t i = 0; i < count; ++i) {  // the exact test on every node, as before the certificate
        double l, s;
        flag[i] = spread_decides(lk[i], sum[i], miss2[i], l, s) ? 1.0 : 0.0;
        lk[i] = l, sum[i] = s;
    }
    return uncertain;
}

bool node_segment_records(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                          const double* Dz, const double* len, double* out, double offset_limit, bool widest) {
    return node_segments(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit, widest);
}

}  // namespace detail
}  // namespace wire
