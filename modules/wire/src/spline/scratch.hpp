// Internal: the curve stage's per-thread working memory (a pool of double arrays) and its block runner.
#pragma once

#include <cassert>
#include <cstddef>
#include <vector>

namespace wire::curve_stage {

// The curve stage's per-node and per-segment passes work on structure-of-arrays scratch (x, y, z arrays, per
// thread, reused across calls) with branch-free bodies, so the compiler vectorizes them across nodes; the rare
// special nodes (a merge, a tensed node, a bad value) are flagged and handled by a scalar pass. Every value is
// computed by the same operations in the same order as the scalar form (vectorizing across independent nodes
// changes no rounding), so the output is bit-identical to it.

// Per-thread pool of double arrays: carve(k) hands out the next k doubles (valid until the next reset).
struct Pool {
    std::vector<double> buf;
    std::size_t used = 0;
    void reset(std::size_t total) {
        if (buf.size() < total) buf.resize(total);
        used = 0;
    }
    double* carve(std::size_t k) {
        assert(used + k <= buf.size() && "Pool::carve: more than reset() asked for");
        double* p = buf.data() + used;
        used += k;
        return p;
    }
};

// Runs an element-wise kernel (element i's outputs from its own inputs only; outputs not read) on [0, count) in
// whole blocks of 8, the AVX-512 clone's vector: run(0, count rounded down to 8), then run(count - 8, 8), which
// rewrites up to 7 elements with the same values. A vector loop over the whole count would end in a 4-wide step
// and up to 3 scalar ones (a quarter of spread_kernel's time on 62 nodes); the second call is one 8-wide step.
template <class Run>
void in_whole_blocks(std::size_t count, Run&& run) {
    constexpr std::size_t kBlock = 8;
    const std::size_t head = count & ~(kBlock - 1);
    if (count < kBlock || head == count) return run(0, count);
    run(0, head);
    run(count - kBlock, kBlock);
}

}  // namespace wire::curve_stage
