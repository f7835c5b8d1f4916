// Internal: the span hierarchy walk (SpanMerger) and the update's per-thread working memory. A header so that the
// update inlines the walk (it runs in lod/update.cpp; lod/update_passes.cpp shares the working memory).
#pragma once

#include "lod/span_kernels.hpp"
#include "lod/view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace wire::lod_stage {

// Per-update working memory of one thread (grows once, then reused).
struct Scratch {
    std::vector<double> z_min, k;  // per segment: hull depth and off-axis factor (hull_depths())
    std::vector<double> raw, clamped;  // per segment: Wang's count and clamp flag (wang_counts())
    std::vector<double> ratios;        // per hierarchy node: SpanMerger's ratios
    std::vector<unsigned char> outside;
    std::vector<uint32_t> old_counts;
    std::vector<uint32_t> walk_a, walk_b;  // SpanMerger::walk_levels: the undecided nodes of two levels
};
inline Scratch& scratch() {
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

}  // namespace wire::lod_stage
