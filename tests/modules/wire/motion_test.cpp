// The first frame moves with the wire (motion.hpp, issue 31): over random families of cables and motions (fixed
// seeds) the rendered frames turn with a rigid motion (per frame and when the pose returns), non-rigid motion
// twists the first frame by no more than the motion's own local rotation, and no frame ever flips.
#include "wire/motion.hpp"
#include "wire/pipeline.hpp"
#include "wire/testing/random.hpp"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

namespace wire {
namespace {

using glm::dvec3;
using glm::dquat;
constexpr double kDeg = 180.0 / std::numbers::pi;

/// Signed angle (degrees) from a to b about axis t (a, b roughly normal to t).
double angle_about(const dvec3& a, const dvec3& b, const dvec3& t) {
    return std::atan2(glm::dot(glm::cross(a, b), t), glm::dot(a, b)) * kDeg;
}

struct Distribution {
    std::vector<double> v;
    void add(double x) { v.push_back(x); }
    double quantile(double q) {
        if (v.empty()) return 0.0;
        std::sort(v.begin(), v.end());
        return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
    }
    std::string text() {
        char buf[160];
        std::snprintf(buf, sizeof buf, "median %.2e p90 %.2e max %.2e deg (%zu)", quantile(0.5), quantile(0.9),
                      quantile(1.0), v.size());
        return buf;
    }
};

/// A random realistic cable: 10-30 nodes, 3-28 m, uniform / end-dense / jittered spacing; a hanging catenary-like
/// sag between two anchors, a coil, or a smooth random curve. Ids 100, 110, ...
WireNodes random_cable(testing::Random& r, int shape, dvec3& anchor_a, dvec3& anchor_b) {
    const int n = r.integer(10, 30);
    const double length = r.uniform(3.0, 28.0);
    const int spacing = r.integer(0, 2);
    std::vector<double> s(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        double x = static_cast<double>(i) / (n - 1);
        if (spacing == 1) x = 0.5 - 0.5 * std::cos(std::numbers::pi * x);  // end-dense
        if (spacing == 2 && i > 0 && i < n - 1) x += r.uniform(-0.3, 0.3) / (n - 1);
        s[static_cast<std::size_t>(i)] = x;
    }
    const dvec3 origin = dvec3(r.uniform(-50, 50), r.uniform(-50, 50), r.uniform(-50, 50));
    const dvec3 e1 = r.unit();
    dvec3 e2 = glm::normalize(glm::cross(e1, r.unit()));
    const dvec3 e3 = glm::cross(e1, e2);
    WireNodes w;
    const double sag = r.uniform(0.05, 0.4) * length, wiggle = r.uniform(0.0, 0.1) * length;
    const double turns = r.uniform(1.0, 4.0), coil_r = r.uniform(0.05, 0.2) * length;
    const double ph1 = r.uniform(0, 6.3), ph2 = r.uniform(0, 6.3);
    for (int i = 0; i < n; ++i) {
        const double x = s[static_cast<std::size_t>(i)];
        dvec3 p;
        if (shape == 0) {  // hanging: e2 is down
            p = origin + x * length * e1 + 4.0 * sag * x * (1.0 - x) * e2 + wiggle * std::sin(3.0 * x + ph1) * e3;
        } else if (shape == 1) {  // coil about e1
            const double a = 2.0 * std::numbers::pi * turns * x;
            p = origin + x * length * e1 + coil_r * (std::cos(a) * e2 + std::sin(a) * e3);
        } else {  // smooth random curve
            p = origin + x * length * e1 + 0.2 * length * std::sin(2.0 * x + ph1) * e2 +
                0.15 * length * std::sin(3.0 * x + ph2) * e3;
        }
        w.positions.push_back(p);
        w.ids.push_back(static_cast<uint32_t>(100 + 10 * i));
    }
    anchor_a = w.positions.front();
    anchor_b = w.positions.back();
    return w;
}

WireNodes moved(const WireNodes& w, const dquat& q, const dvec3& pivot, const dvec3& shift) {
    WireNodes out = w;
    for (dvec3& p : out.positions) p = pivot + q * (p - pivot) + shift;
    return out;
}

PipelineSettings settings_for(int spline) {
    PipelineSettings s;
    s.spline.kind = spline == 0 ? SplineKind::automatic : SplineKind::catmull_rom;
    s.spline.alpha = spline == 1 ? 1.0 : 0.5;
    s.tessellate.rings_per_segment = 4;
    return s;
}

/// Per ring of two successive states under a known rigid step q: the twist of the new normal against the old
/// normal carried by q (degrees).
void rigid_twists(const RingSet& before, const RingSet& after, const dquat& q, Distribution& d, double& worst) {
    ASSERT_EQ(before.frames.size(), after.frames.size());
    for (std::size_t i = 0; i < after.frames.size(); ++i) {
        const double a = std::abs(angle_about(q * before.frames[i].r, after.frames[i].r, after.frames[i].t));
        d.add(a);
        worst = std::max(worst, a);
    }
}

// Rigid families: rotations about random axes through random pivots at 0.5-5 degrees a frame and back, a hanging
// cable swinging as a pendulum about the line through its anchors (50 degrees, 1.5 s at 60 Hz), dragged (turning
// while its pivot slides), a coil turning about its own axis, a rotation about the line of the first element.
TEST(MotionTest, FramesTurnWithRigidMotion) {
    Distribution per_frame[5], returned[5];
    const char* names[5] = {"random axes", "pendulum", "dragged", "coil about its axis", "about the first element"};
    double worst_frame = 0.0, worst_return = 0.0;
    int cases = 0;
    for (int c = 0; c < 150; ++c) {
        testing::Random r{0xC0FFEEull + static_cast<uint64_t>(c) * 0x9E3779B97F4A7C15ull};
        const int family = c % 5;
        dvec3 a, b;
        const int shape = family == 1 ? 0 : family == 3 ? 1 : r.integer(0, 2);
        const WireNodes rest = random_cable(r, shape, a, b);
        const PipelineSettings settings = settings_for(c % 3);
        // The pose at step k (k = 0..steps), going out and coming back to k = 0.
        dvec3 axis = r.unit(), pivot = rest.positions[static_cast<std::size_t>(r.integer(0, 9))];
        const double rate = r.uniform(0.5, 5.0) / kDeg;
        dvec3 slide(0.0);
        int steps = 20;
        std::function<double(int)> angle = [&](int k) { return rate * k; };
        if (family == 1) {
            axis = glm::normalize(b - a), pivot = a, steps = 90;
            angle = [](int k) { return 50.0 / kDeg * std::sin(2.0 * std::numbers::pi * k / 90.0); };
        } else if (family == 2) {
            slide = r.unit() * r.uniform(0.01, 0.2);
        } else if (family == 3) {
            axis = glm::normalize(rest.positions.back() - rest.positions.front()), pivot = rest.positions.front();
        } else if (family == 4) {
            axis = glm::normalize(rest.positions[1] - rest.positions[0]), pivot = rest.positions[0];
        }
        const auto pose_q = [&](int k) { return glm::angleAxis(angle(k), axis); };
        std::vector<int> path;
        for (int k = 0; k <= steps; ++k) path.push_back(k);
        if (family != 1)
            for (int k = steps - 1; k >= 0; --k) path.push_back(k);
        WirePipeline pipe;
        std::vector<RingSet> sets;
        for (int k : path) {
            const WireNodes nodes = moved(rest, pose_q(k), pivot, slide * static_cast<double>(k));
            ASSERT_TRUE(pipe.update(nodes, settings).ok()) << "case " << c;
            sets.push_back(pipe.rings());
        }
        for (std::size_t f = 1; f < path.size(); ++f) {
            const dquat step = pose_q(path[f]) * glm::inverse(pose_q(path[f - 1]));
            rigid_twists(sets[f - 1], sets[f], step, per_frame[family], worst_frame);
        }
        // Back at pose 0 (or pose 0 again after the pendulum's period): the frames of the start.
        const RingSet& first = sets.front();
        const RingSet& last = sets.back();
        ASSERT_EQ(first.frames.size(), last.frames.size());
        for (std::size_t i = 0; i < last.frames.size(); ++i) {
            const double e = std::abs(angle_about(first.frames[i].r, last.frames[i].r, last.frames[i].t));
            returned[family].add(e);
            worst_return = std::max(worst_return, e);
        }
        ++cases;
    }
    for (int f = 0; f < 5; ++f) {
        std::printf("%-24s per frame: %s; pose returned: %s\n", names[f], per_frame[f].text().c_str(),
                    returned[f].text().c_str());
    }
    EXPECT_LE(worst_frame, 0.05) << "twist per frame against the rigidly carried frame";
    EXPECT_LE(worst_return, 0.05) << "twist when the same pose returns";
    EXPECT_EQ(cases, 150);
}

/// The largest rotation angle (degrees) of any stretch of four consecutive nodes between two states: the motion's
/// own local rotation (a stretch whose nodes do not fix a rotation counts its elements' turns instead).
double largest_local_rotation(const WireNodes& before, const WireNodes& after) {
    double largest = 0.0;
    const std::size_t n = before.size();
    for (std::size_t i = 0; i + 1 < n; ++i) {
        const dvec3 e0 = glm::normalize(before.positions[i + 1] - before.positions[i]);
        const dvec3 e1 = glm::normalize(after.positions[i + 1] - after.positions[i]);
        largest = std::max(largest, std::acos(std::clamp(glm::dot(e0, e1), -1.0, 1.0)) * kDeg);
    }
    for (std::size_t i = 0; i + 4 <= n; ++i) {
        WireNodes a, b;
        for (std::size_t k = i; k < i + 4; ++k) {
            a.positions.push_back(before.positions[k]), a.ids.push_back(before.ids[k]);
            b.positions.push_back(after.positions[k]), b.ids.push_back(after.ids[k]);
        }
        const MotionFit f = fit_motion(motion_reference(a), b);
        if (f.confidence < 1.0) continue;
        largest = std::max(largest, 2.0 * std::acos(std::clamp(std::abs(f.rotation.w), 0.0, 1.0)) * kDeg);
    }
    return largest;
}

// Non-rigid motion (a wave running along the cable: the whipping of a swung rope, or a cable shaken by its start):
// the first frame turns about its tangent, beyond the smallest rotation of the tangent, by no more than the motion's
// own rotation near the start (the rotation fitted to the nodes within the reach that fixes it, plus the tangent's
// departure from it); no ring's normal flips (beyond the smallest rotation of its tangent it turns by less than 90
// degrees a frame). Reported beside: the twist against the largest rotation of any four consecutive nodes (a
// nearly straight start borrows the rotation of the bend further along, which can exceed it).
TEST(MotionTest, NonRigidTwistBoundedByTheMotion) {
    Distribution ratio, flips, bound;
    double worst_ratio = 0.0, worst_flip = 0.0;
    int worst_case = -1;
    for (int c = 0; c < 60; ++c) {
        testing::Random r{0xBADCAB1Eull + static_cast<uint64_t>(c) * 0x9E3779B97F4A7C15ull};
        dvec3 a, b;
        const WireNodes rest = random_cable(r, r.integer(0, 2), a, b);
        const PipelineSettings settings = settings_for(c % 3);
        const dvec3 dir = r.unit();
        // Resolved by the nodes (8 or more a wavelength) and not folding the rope (slope of the wave at most 0.5).
        const double span = glm::length(b - a);
        const double waves = r.uniform(0.5, std::max(0.6, static_cast<double>(rest.size()) / 8.0));
        const double amp = r.uniform(0.1, 1.0) * 0.5 * span / (2.0 * std::numbers::pi * waves);
        const double speed = r.uniform(0.005, 0.03);  // waves per frame
        WirePipeline pipe;
        RingSet before;
        WireNodes prev;
        for (int k = 0; k < 60; ++k) {
            WireNodes nodes = rest;
            const std::size_t n = nodes.size();
            for (std::size_t i = 0; i < n; ++i) {
                const double x = static_cast<double>(i) / static_cast<double>(n - 1);
                const double phase = 2.0 * std::numbers::pi * (waves * x - speed * k);
                const double envelope = c % 2 == 0 ? x : 1.0 - x;  // whipped at the far end, or shaken at the start
                nodes.positions[i] += amp * envelope * std::sin(phase) * dir;
            }
            ASSERT_TRUE(pipe.update(nodes, settings).ok());
            const RingSet& now = pipe.rings();
            if (k > 0) {
                const double local = largest_local_rotation(prev, nodes);
                // Twist of ring 0 beyond the smallest rotation of its tangent (what the projection gives).
                const auto twist_at = [&](std::size_t i) {
                    const dvec3 t = now.frames[i].t, r0 = before.frames[i].r;
                    const dvec3 projected = glm::normalize(r0 - glm::dot(r0, t) * t);
                    return std::abs(angle_about(projected, now.frames[i].r, t));
                };
                const double twist = twist_at(0);
                const double q = twist / std::max(local, 1e-12);
                ratio.add(q);
                if (q > worst_ratio) worst_ratio = q, worst_case = c;
                // The bound: a rotation's twist about any axis is at most its angle. The first frame twists by the
                // fitted rotation's twist about the tangent, plus what the tangent's departure from the fitted
                // rotation adds through the projection.
                const MotionFit fit = fit_motion(motion_reference(prev), nodes);
                const double fit_deg = 2.0 * std::acos(std::min(1.0, std::abs(fit.rotation.w))) * kDeg * fit.confidence;
                const double off_deg = std::acos(std::clamp(glm::dot(fit.rotation * before.frames[0].t, now.frames[0].t),
                                                            -1.0, 1.0)) * kDeg;
                EXPECT_LE(twist, fit_deg + off_deg + 1e-9) << "case " << c << " frame " << k;
                bound.add(twist / std::max(fit_deg + off_deg, 1e-12));
                if (now.frames.size() == before.frames.size())
                    for (std::size_t i = 0; i < now.frames.size(); ++i) {
                        const double f = twist_at(i);
                        flips.add(f);
                        worst_flip = std::max(worst_flip, f);
                    }
            }
            before = now;
            prev = nodes;
        }
    }
    std::printf("non-rigid: first-frame twist / largest local rotation: %s (ratio, worst case %d)\n",
                ratio.text().c_str(), worst_case);
    std::printf("non-rigid: first-frame twist / (fitted rotation + tangent departure): %s (ratio)\n",
                bound.text().c_str());
    std::printf("non-rigid: every ring's twist beyond its tangent's turn, per frame: %s\n", flips.text().c_str());
    EXPECT_LT(worst_flip, 90.0) << "no flip";
}

// The fit itself: exact on a rigid motion (any weights), none without three matched ids, and it gives way to the
// projection on a straight wire (whose twist about itself is not in its nodes).
TEST(MotionTest, FitExactDegenerateAndStraight) {
    testing::Random r{77};
    dvec3 a, b;
    const WireNodes w = random_cable(r, 2, a, b);
    const dquat q = glm::angleAxis(0.7, r.unit());
    const MotionFit fit = fit_motion(motion_reference(w), moved(w, q, dvec3(3, -2, 5), dvec3(1e3, 0, 0)));
    EXPECT_EQ(fit.confidence, 1.0);
    EXPECT_LT(glm::length(fit.rotation * dvec3(0.3, -0.5, 0.8) - q * dvec3(0.3, -0.5, 0.8)), 1e-12);

    WireNodes renamed = w;
    for (uint32_t& id : renamed.ids) id += 1;  // every id replaced: nothing to match
    EXPECT_EQ(fit_motion(motion_reference(w), renamed).confidence, 0.0);

    WireNodes straight;
    for (int i = 0; i < 12; ++i) straight.positions.push_back(dvec3(0.5 * i, 1.0, 2.0));
    const MotionFit s = fit_motion(motion_reference(straight), moved(straight, q, dvec3(0.0), dvec3(0.0)));
    EXPECT_EQ(s.confidence, 0.0) << "collinear nodes do not fix the rotation about their line";
    EXPECT_EQ(carry_normal(s, dvec3(0, 0, 1)), dvec3(0, 0, 1));
}

}  // namespace
}  // namespace wire
