// `wiretool bench`, part 2: speed against error. Reference scenes whose exact answer is generated in code
// (catenary, helix, stretched run + tight bend, hairpin, smooth random curve, churn), every spline method,
// three frame methods and five LOD tolerances; per row time, size, world/screen/twist error and pops. Writes
// accuracy.csv, accuracy.md, stability.md and speed_vs_error.png (gnuplot, when installed).
#include "bench/common.hpp"
#include "bench/accuracy/families.hpp"
#include "wiretool/commands.hpp"

#include <wire/bezier.hpp>
#include <wire/frames.hpp>
#include <wire/lod.hpp>
#include <wire/multires.hpp>
#include <wire/testing/reference.hpp>
#include <wire/rings.hpp>
#include <wire/spline.hpp>
#include <wire/tessellate.hpp>
#include <wire/tube.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTolerancesPx[] = {0.1, 0.25, 0.5, 1.0, 2.0};
constexpr float kRadiusM = 0.01f;
/// Samples per segment of the pop metric (--quick: 96). Its polyline error is ~h^2 k / 8: at 32 a strongly
/// overshooting 2 m segment (chordal on the stretched run) reads a 1.1 mm pop that 256 samples show to be
/// 0.02 mm.
constexpr int kPopSamplesPerSegment = 256;
constexpr int kQuickPopSamplesPerSegment = 96;

// ---- scenes
// -------------------------------------------------------------------------------------------------

/// A scene: one wire's nodes, taken from an exact curve at known parameters, and how to measure against it.
struct Scene {
    std::string name;
    std::string description;
    wire::WireNodes nodes;  ///< with ids (the pop events and churn need them)
    float stretch = 1.0f;   ///< for the physics arrays of the curvature-tension method
    // Truth: an exact catenary, or a dense polyline of the exact curve with the curve parameter of every
    // sample and of every node (so a query only searches near its own segment).
    bool catenary_truth = false;
    wire::Catenary catenary;
    std::vector<glm::dvec3> dense;
    std::vector<double> dense_param;
    std::vector<double> node_param;
    /// Only the first `straight_segments` segments are measured, against the line y = z = 0 (stretched run).
    uint32_t straight_segments = 0;
    bool churn = false;
    wire::LodView view;
};

/// Sets a camera that sees the whole wire at 1920x1080, 60 degrees, from slightly above and to the side.
void frame_camera(Scene& s) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::dvec3& p : s.nodes.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * glm::length(hi - lo), 0.1);
    const double fov = kPi / 3.0;
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.25, 0.35, 1.0));
    s.view = wire::LodView::perspective(centre + dir * (1.1 * radius / std::tan(0.5 * fov)), centre,
                                        glm::dvec3(0.0, 1.0, 0.0), fov, 1920.0, 1080.0, 0.1, 1000.0);
}

void set_ids(wire::WireNodes& n) {
    n.ids.clear();
    for (std::size_t i = 0; i < n.positions.size(); ++i) n.ids.push_back(static_cast<uint32_t>(100 + 10 * i));
}

/// Nodes at `params` of `curve`, plus the dense truth polyline (`dense_count` samples over [p0, p1]).
void sample_truth(Scene& s, const std::function<glm::dvec3(double)>& curve, const std::vector<double>& params,
                  double p0, double p1, int dense_count) {
    s.node_param = params;
    for (double p : params) s.nodes.positions.push_back(curve(p));
    for (int i = 0; i <= dense_count; ++i) {
        const double p = p0 + (p1 - p0) * i / dense_count;
        s.dense.push_back(curve(p));
        s.dense_param.push_back(p);
    }
    set_ids(s.nodes);
}

/// The 20 m cable of DESIGN 4.8 between (0,0,0) and (16,2,0), 16 nodes dense near the ends
/// (s = L (1 - cos(pi i/15))/2: neighbour ratio ~10).
Scene catenary_scene(const std::string& name) {
    Scene s;
    s.name = name;
    s.description =
        "20 m catenary (0,0,0)-(16,2,0), 16 nodes at s = L(1-cos(pi i/15))/2 (dense near the ends)";
    s.catenary_truth = true;
    (void)s.catenary.solve(glm::dvec3(0.0), glm::dvec3(16.0, 2.0, 0.0), 20.0);
    std::vector<double> arc;
    for (int i = 0; i < 16; ++i)
        arc.push_back(s.catenary.length_m() * 0.5 * (1.0 - std::cos(kPi * i / 15.0)));
    s.nodes.positions = s.catenary.points_at_arc_lengths(arc);
    set_ids(s.nodes);
    return s;
}

Scene helix_scene() {
    Scene s;
    s.name = "helix";
    s.description = "helix radius 1 m, pitch 0.3 m/rad, 3 turns, 12 nodes per turn (exact RMF: DESIGN 4.3)";
    const double a = 1.0, b = 0.3;
    std::vector<double> params;
    for (int i = 0; i <= 36; ++i) params.push_back(2.0 * kPi * i / 12.0);
    sample_truth(
        s, [&](double th) { return glm::dvec3(a * std::cos(th), a * std::sin(th), b * th); }, params, 0.0,
        params.back(), 40000);
    return s;
}

/// Stretched 6% along +x (nodes every 2 m to x = 10), a 0.1 m element turning 90 degrees down, then long
/// elements: the straight run must stay on its line.
Scene stretched_bend_scene() {
    Scene s;
    s.name = "stretched_bend";
    s.description =
        "6% stretched straight run (nodes every 2 m), 0.1 m element turning 90 deg, long run down; "
        "world error = distance off the straight line over the run";
    for (int i = 0; i <= 5; ++i) s.nodes.positions.emplace_back(2.0 * i, 0.0, 0.0);
    s.nodes.positions.emplace_back(10.0, -0.1, 0.0);
    s.nodes.positions.emplace_back(10.0, -2.1, 0.0);
    s.nodes.positions.emplace_back(10.0, -4.1, 0.0);
    s.stretch = 1.06f;
    s.nodes.stretch.assign(s.nodes.positions.size(), s.stretch);
    s.straight_segments = 5;
    set_ids(s.nodes);
    return s;
}

/// Two 5 m legs 0.5 m apart joined by a half circle of radius 0.25 m; nodes every metre on the legs and at
/// every 45 degrees on the turn.
Scene hairpin_scene() {
    Scene s;
    s.name = "hairpin";
    s.description =
        "hairpin: two 5 m legs joined by a half circle of radius 0.25 m, nodes every 1 m and every 45 deg";
    const double r = 0.25, leg = 5.0, arc = kPi * r;
    auto u_shape = [=](double p) {  // p = arc length from the start of the first leg
        if (p <= leg) return glm::dvec3(leg - p, r, 0.0);
        if (p <= leg + arc) {
            const double a = (p - leg) / r;
            return glm::dvec3(-r * std::sin(a), r * std::cos(a), 0.0);
        }
        return glm::dvec3(p - leg - arc, -r, 0.0);
    };
    std::vector<double> params;
    for (int i = 0; i <= 5; ++i) params.push_back(i);
    for (int k = 1; k <= 3; ++k) params.push_back(leg + arc * k / 4.0);
    for (int i = 0; i <= 5; ++i) params.push_back(leg + arc + i);
    sample_truth(s, u_shape, params, 0.0, params.back(), 20000);
    return s;
}

/// A smooth random curve (random Fourier series, fixed seed) through 40 nodes at random spacing (ratio up to
/// ~4).
Scene random_walk_scene() {
    Scene s;
    s.name = "random_walk";
    s.description =
        "smooth random 3D curve (6-term random Fourier series, ~12 m) through 40 nodes at random spacing";
    unsigned seed = 12345u;
    auto rnd = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return (seed >> 8) * (1.0 / 16777216.0) - 0.5;
    };
    std::vector<glm::dvec3> ca, cb;
    for (int k = 1; k <= 6; ++k) {
        ca.emplace_back(rnd(), rnd(), rnd());
        cb.emplace_back(rnd(), rnd(), rnd());
    }
    auto curve = [=](double p) {
        glm::dvec3 x(8.0 * p, 0.0, 0.0);
        for (int k = 1; k <= 6; ++k)
            x += (2.0 / k) * (ca[static_cast<std::size_t>(k - 1)] * std::sin(2 * kPi * k * p) +
                              cb[static_cast<std::size_t>(k - 1)] * std::cos(2 * kPi * k * p));
        return x;
    };
    std::vector<double> params{0.0};
    std::vector<double> steps;
    for (int i = 0; i < 39; ++i) steps.push_back(0.4 + rnd() + 0.5);  // in [0.4, 1.4]
    double total = 0.0;
    for (double st : steps) total += st;
    for (double st : steps) params.push_back(params.back() + st / total);
    params.back() = 1.0;
    sample_truth(s, curve, params, 0.0, 1.0, 40000);
    return s;
}

// ---- measurements
// -----------------------------------------------------------------------------------------------

double point_segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

/// Distance from p (a point drawn for curve segment `segment`) to the scene's exact curve.
double truth_distance(const Scene& s, const glm::dvec3& p, const wire::Curve& curve, uint32_t segment) {
    if (s.catenary_truth) return s.catenary.distance(p);
    // Search the dense truth between the nodes one before and two after the segment's start node.
    const std::size_t n = s.node_param.size();
    const std::size_t first = curve.source_node[segment];
    const std::size_t last = segment + 1 < curve.node_count() ? curve.source_node[segment + 1] : n - 1;
    const double p0 = s.node_param[first > 0 ? first - 1 : 0];
    const double p1 = s.node_param[std::min(last + 1, n - 1)];
    auto lo = std::lower_bound(s.dense_param.begin(), s.dense_param.end(), p0);
    auto hi = std::upper_bound(s.dense_param.begin(), s.dense_param.end(), p1);
    std::size_t i0 = static_cast<std::size_t>(lo - s.dense_param.begin());
    std::size_t i1 = std::min(static_cast<std::size_t>(hi - s.dense_param.begin()), s.dense.size() - 1);
    if (i0 > 0) --i0;
    double best = 1e300;
    for (std::size_t i = i0; i < i1; ++i)
        best = std::min(best, point_segment_distance(p, s.dense[i], s.dense[i + 1]));
    return best;
}

/// Largest distance of the drawn centre polyline (ring centres, 4 points per ring interval) to the exact
/// curve; for the stretched run: largest distance off the line y = z = 0 over its first straight_segments
/// segments.
double world_error_m(const Scene& s, const wire::Curve& curve, const std::vector<wire::RingParam>& params) {
    double worst = 0.0;
    for (std::size_t i = 0; i < params.size(); ++i) {
        const glm::dvec3 a = wire::position(curve.segments[params[i].segment], params[i].t);
        const bool last = i + 1 == params.size();
        const glm::dvec3 b =
            last ? a : wire::position(curve.segments[params[i + 1].segment], params[i + 1].t);
        for (int q = 0; q < (last ? 1 : 4); ++q) {
            const glm::dvec3 p = a + (b - a) * (q / 4.0);
            if (s.straight_segments > 0) {
                if (params[i].segment < s.straight_segments &&
                    (last || params[i + 1].segment < s.straight_segments))
                    worst = std::max(worst, std::hypot(p.y, p.z));
            } else {
                worst = std::max(worst, truth_distance(s, p, curve, params[i].segment));
            }
        }
    }
    return worst;
}

/// Ring parameters with `sub` steps per ring interval (ring i of `params` is entry i*sub), for a reference
/// RMF.
std::vector<wire::RingParam> refine(const std::vector<wire::RingParam>& params, int sub) {
    std::vector<wire::RingParam> out;
    for (std::size_t i = 0; i + 1 < params.size(); ++i) {
        const wire::RingParam a = params[i], b = params[i + 1];
        const double tb = b.segment == a.segment ? b.t : 1.0;
        for (int k = 0; k < sub; ++k) out.push_back({a.segment, a.t + (tb - a.t) * k / sub});
    }
    out.push_back(params.back());
    return out;
}

/// Largest angle (degrees) between each ring's normal and the rotation-minimizing frame of the same curve at
/// the same parameter, both seeded alike at ring 0. The reference is double reflection with 64 steps per ring
/// interval (fourth order: converged to ~1e-9 degrees), so this isolates the frame method from the spline.
double twist_error_deg(const wire::Curve& curve, const std::vector<wire::RingParam>& params,
                       const wire::RingSet& rings) {
    constexpr int kSub = 64;
    const std::vector<wire::RingParam> fine = refine(params, kSub);
    wire::RingSet ref;
    wire::build_rings(curve, fine, {}, ref);
    double worst = 0.0;
    for (std::size_t i = 0; i < rings.frames.size(); ++i) {
        const wire::Frame& g = ref.frames[i * kSub];
        const wire::Frame& f = rings.frames[i];
        worst =
            std::max(worst, std::abs(std::atan2(glm::dot(glm::cross(g.r, f.r), g.t), glm::dot(g.r, f.r))));
    }
    return worst * 180.0 / kPi;
}

// ---- methods
// ----------------------------------------------------------------------------------------------------

struct Method {
    std::string name;
    wire::SplineSettings spline;
    wire::FrameMethod frames = wire::FrameMethod::double_reflection;
    bool physics = false;    ///< curvature tension from per-node physics arrays
    std::string spline_key;  ///< methods with the same curve share their pop measurement
};

std::vector<Method> methods() {
    using wire::SplineKind;
    return {
        {"linear", {.kind = SplineKind::linear}, {}, false, "linear"},
        {"uniform", {.kind = SplineKind::catmull_rom, .alpha = 0.0}, {}, false, "uniform"},
        {"centripetal", {.kind = SplineKind::catmull_rom, .alpha = 0.5}, {}, false, "centripetal"},
        {"chordal", {.kind = SplineKind::catmull_rom, .alpha = 1.0}, {}, false, "chordal"},
        {"c2", {.kind = SplineKind::c2}, {}, false, "c2"},
        {"auto", {.kind = SplineKind::automatic}, {}, false, "auto"},
        {"curvature_tension",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5, .curvature_tension = true},
         {},
         true,
         "curvature_tension"},
        {"centripetal+rotation",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5},
         wire::FrameMethod::rotation,
         false,
         "centripetal"},
        {"centripetal+projection",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5},
         wire::FrameMethod::projection,
         false,
         "centripetal"},
    };
}

/// The thesis' physics per node for curvature tension: theta = turning angle, L = the two adjacent elements,
/// dL = L (stretch - 1), a solid round section of the wire's radius (Iz = pi r^4/4, A = pi r^2).
void add_physics(wire::WireNodes& n, float stretch) {
    const std::size_t count = n.positions.size();
    n.theta_rad.assign(count, 0.0);
    n.iz_m4.assign(count, kPi * std::pow(kRadiusM, 4) / 4.0);
    n.area_m2.assign(count, kPi * kRadiusM * kRadiusM);
    n.length_m.assign(count, 0.0);
    n.delta_length_m.assign(count, 0.0);
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 in = i > 0 ? n.positions[i] - n.positions[i - 1] : glm::dvec3(0.0);
        const glm::dvec3 out = i + 1 < count ? n.positions[i + 1] - n.positions[i] : glm::dvec3(0.0);
        const double li = glm::length(in), lo = glm::length(out);
        if (li > 0.0 && lo > 0.0)
            n.theta_rad[i] = std::acos(std::clamp(glm::dot(in, out) / (li * lo), -1.0, 1.0));
        n.length_m[i] = li + lo;
        n.delta_length_m[i] = (li + lo) * (static_cast<double>(stretch) - 1.0);
    }
}

/// Inserts a node before `at` with id `id`, copying the neighbour's optional per-node entries (physics
/// included).
void insert_node(wire::WireNodes& n, std::size_t at, const glm::dvec3& p, uint32_t id) {
    auto dup = [at](auto& v) {
        if (v.empty()) return;
        const auto value = v[std::min(at, v.size() - 1)];
        v.insert(v.begin() + static_cast<std::ptrdiff_t>(at), value);
    };
    n.positions.insert(n.positions.begin() + static_cast<std::ptrdiff_t>(at), p);
    n.ids.insert(n.ids.begin() + static_cast<std::ptrdiff_t>(at), id);
    dup(n.stretch), dup(n.radius_m), dup(n.theta_rad), dup(n.iz_m4), dup(n.length_m), dup(n.delta_length_m),
        dup(n.area_m2);
}

void remove_node(wire::WireNodes& n, std::size_t at) {
    auto erase = [at](auto& v) {
        if (at < v.size()) v.erase(v.begin() + static_cast<std::ptrdiff_t>(at));
    };
    erase(n.positions), erase(n.ids), erase(n.stretch), erase(n.radius_m), erase(n.theta_rad), erase(n.iz_m4),
        erase(n.length_m), erase(n.delta_length_m), erase(n.area_m2);
}

// ---- the pipeline of one wire, timed
// --------------------------------------------------------------------------

struct WireOutput {
    wire::Curve curve;
    wire::WireLod lod;
    std::vector<wire::RingParam> params;
    wire::RingSet rings;
    wire::TubeMesh mesh;
};

/// lod -> rings [-> mesh] for a built curve.
void tessellate(const wire::LodView& view, double tolerance_px, wire::FrameMethod frames, bool mesh,
                WireOutput& w) {
    w.lod = {};
    (void)wire::update_lod(w.curve, view, {.tolerance_px = tolerance_px, .hysteresis_band = -1.0}, w.lod);
    if (w.lod.counts.empty())
        w.lod.counts.assign(w.curve.segment_count(), 1u);  // culled: never in these scenes
    wire::place_rings(w.curve, w.lod.counts, w.params);
    wire::RingSettings rs;
    rs.frames.method = frames;
    wire::build_rings(w.curve, w.params, rs, w.rings);
    if (mesh) wire::build_tube(w.rings, {.sides = std::max(3u, w.lod.sides)}, w.mesh);
}

/// Median over 3 trials of the CPU time of one call of `fn`, microseconds (each trial repeats `fn` until it
/// has used at least `min_ms`).
double time_us(const std::function<void()>& fn, double min_ms) {
    std::vector<double> trials;
    for (int t = 0; t < 3; ++t) {
        int reps = 0;
        const double c0 = cpu_ms();
        double used = 0.0;
        do {
            fn();
            ++reps;
            used = cpu_ms() - c0;
        } while (used < min_ms);
        trials.push_back(1e3 * used / reps);
    }
    return median(trials);
}

// ---- pops
// -------------------------------------------------------------------------------------------------------

struct Pops {
    double no_remedy_m = 0.0;
    double remedy_m = 0.0;
};

/// Runs `states` (each shown for at least one frame, then held until the geomorph ends) and returns the
/// largest jump between consecutive rendered curves, with and without the remedy.
Pops measure_pops(const std::vector<wire::WireNodes>& states, const wire::SplineSettings& spline,
                  int hold_frames, int samples) {
    Pops out;
    for (bool remedy : {false, true}) {
        wire::MultiresCurve m({.spline = spline, .geomorph = remedy});
        wire::Curve prev, cur;
        bool first = true;
        double worst = 0.0;
        for (const wire::WireNodes& st : states) {
            for (int f = 0; f < std::max(1, hold_frames); ++f) {
                if (!m.update(st, cur)) break;
                if (!first) worst = std::max(worst, wire::curve_jump_m(prev, cur, samples));
                first = false;
                prev = cur;
                if (f > 0 && !m.blending()) break;
            }
        }
        (remedy ? out.remedy_m : out.no_remedy_m) = worst;
    }
    return out;
}

/// One event on a static scene: a node inserted exactly on the curve in the middle of the middle segment,
/// then an original interior node removed.
Pops event_pops(const wire::WireNodes& nodes, const wire::SplineSettings& spline, int samples) {
    wire::Curve c;
    if (!wire::build_curve(nodes, spline, c) || c.segment_count() < 3) return {};
    const std::size_t seg = c.segment_count() / 2;
    wire::WireNodes inserted = nodes;
    insert_node(inserted, c.source_node[seg] + 1, wire::position(c.segments[seg], 0.5), 99999u);
    wire::WireNodes removed = inserted;
    const std::size_t victim = std::max<std::size_t>(1, c.source_node[seg] / 2);
    remove_node(removed, victim);
    return measure_pops({nodes, inserted, removed}, spline, 400, samples);
}

/// Churn: the catenary's nodes while the simulation refines and coarsens: every 5 frames an event, two of
/// every three insert a node exactly on the rendered target curve (middle of a random segment), the third
/// removes a random one of the inserted nodes (coarsening undoes refinement; the original nodes stay, as the
/// posts and the physics' coarsest level would). The states of every frame, in order.
std::vector<wire::WireNodes> churn_states(const wire::WireNodes& start, const wire::SplineSettings& spline,
                                          int frames) {
    std::vector<wire::WireNodes> states;
    wire::WireNodes n = start;
    const uint32_t first_inserted_id = 5000;
    unsigned seed = 777u;
    auto rnd = [&seed](std::size_t k) {
        seed = seed * 1664525u + 1013904223u;
        return static_cast<std::size_t>((seed >> 8) % k);
    };
    uint32_t next_id = first_inserted_id;
    for (int f = 0; f < frames; ++f) {
        if (f > 0 && f % 5 == 0) {
            if ((f / 5) % 3 != 0) {
                wire::Curve c;
                if (wire::build_curve(n, spline, c)) {
                    const std::size_t seg = rnd(c.segment_count());
                    insert_node(n, c.source_node[seg] + 1, wire::position(c.segments[seg], 0.5), next_id++);
                }
            } else {
                std::vector<std::size_t> inserted;
                for (std::size_t i = 0; i < n.ids.size(); ++i)
                    if (n.ids[i] >= first_inserted_id) inserted.push_back(i);
                if (!inserted.empty()) remove_node(n, inserted[rnd(inserted.size())]);
            }
        }
        states.push_back(n);
    }
    return states;
}

Pops churn_pops(const std::vector<wire::WireNodes>& states, const wire::SplineSettings& spline, int samples) {
    return measure_pops(states, spline, 1, samples);
}

// ---- rows
// -------------------------------------------------------------------------------------------------------

struct Row {
    std::string scene, method;
    double tolerance_px = 0.0;
    std::size_t rings = 0, sides = 0, vertices = 0, bytes_cpu = 0, bytes_gpu = 0;
    double ns_per_vertex = 0.0, us_cpu = 0.0, us_gpu = 0.0;
    double world_m = 0.0, screen_px = 0.0, twist_deg = 0.0, pop_m = 0.0, pop_remedy_m = 0.0;
};

std::vector<std::string> to_cells(const Row& r) {
    return {r.scene,
            r.method,
            num(r.tolerance_px),
            num(r.rings),
            num(r.sides),
            num(r.vertices),
            num(r.bytes_cpu),
            num(r.bytes_gpu),
            num(r.ns_per_vertex),
            num(r.us_cpu),
            num(r.us_gpu),
            num(r.world_m),
            num(r.screen_px),
            num(r.twist_deg),
            num(r.pop_m),
            num(r.pop_remedy_m)};
}

Row measure_row(const Scene& s, const Method& m, const wire::WireNodes& nodes, double tol, double min_ms) {
    Row r;
    r.scene = s.name;
    r.method = m.name;
    r.tolerance_px = tol;
    WireOutput w;
    if (!wire::build_curve(nodes, m.spline, w.curve)) {
        r.world_m = r.screen_px = NAN;
        return r;
    }
    tessellate(s.view, tol, m.frames, true, w);
    r.rings = w.params.size();
    r.sides = w.lod.sides;
    r.vertices = w.mesh.vertices.size();
    r.bytes_cpu = cpu_mesh_bytes(1, w.mesh.vertices.size(), w.mesh.indices.size());
    r.bytes_gpu = gpu_rings_bytes(1, w.rings.rings.size());
    r.world_m = world_error_m(s, w.curve, w.params);
    r.screen_px = wire::measure_screen_error(w.curve, w.params, s.view, 256).max_px;
    r.twist_deg = twist_error_deg(w.curve, w.params, w.rings);

    WireOutput t;
    r.us_cpu = time_us(
        [&] {
            (void)wire::build_curve(nodes, m.spline, t.curve);
            tessellate(s.view, tol, m.frames, true, t);
        },
        min_ms);
    r.us_gpu = time_us(
        [&] {
            (void)wire::build_curve(nodes, m.spline, t.curve);
            tessellate(s.view, tol, m.frames, false, t);
        },
        min_ms);
    r.ns_per_vertex = r.vertices > 0 ? 1e3 * r.us_cpu / static_cast<double>(r.vertices) : 0.0;
    return r;
}

/// Churn rows: every frame's state through the pop-free curve stage, then lod/rings/mesh; time per frame,
/// errors as the worst over the frames (world error against the catenary, which the inserted nodes lie near,
/// not on).
Row measure_churn_row(const Scene& s, const Method& m, const std::vector<wire::WireNodes>& states,
                      double tol) {
    Row r;
    r.scene = s.name;
    r.method = m.name;
    r.tolerance_px = tol;
    wire::MultiresCurve multires({.spline = m.spline});
    WireOutput w;
    std::vector<double> us;
    std::size_t frames = 0;
    for (std::size_t f = 0; f < states.size(); ++f) {
        const double c0 = cpu_ms();
        if (!multires.update(states[f], w.curve)) continue;
        tessellate(s.view, tol, m.frames, true, w);
        us.push_back(1e3 * (cpu_ms() - c0));
        ++frames;
        r.rings = std::max(r.rings, w.params.size());
        r.sides = std::max<std::size_t>(r.sides, w.lod.sides);
        r.vertices = std::max(r.vertices, w.mesh.vertices.size());
        r.bytes_cpu = std::max(r.bytes_cpu, cpu_mesh_bytes(1, w.mesh.vertices.size(), w.mesh.indices.size()));
        r.bytes_gpu = std::max(r.bytes_gpu, gpu_rings_bytes(1, w.rings.rings.size()));
        if (f % 10 == 0 || f + 1 == states.size()) {
            r.world_m = std::max(r.world_m, world_error_m(s, w.curve, w.params));
            r.screen_px =
                std::max(r.screen_px, wire::measure_screen_error(w.curve, w.params, s.view, 128).max_px);
            r.twist_deg = std::max(r.twist_deg, twist_error_deg(w.curve, w.params, w.rings));
        }
    }
    r.us_cpu = median(us);
    r.us_gpu =
        r.us_cpu;  // the frame cost is dominated by the pop-free curve stage; the tube is not split out here
    r.ns_per_vertex = r.vertices > 0 ? 1e3 * r.us_cpu / static_cast<double>(r.vertices) : 0.0;
    (void)frames;
    return r;
}

// ---- outputs
// ----------------------------------------------------------------------------------------------------

const Row* find_row(const std::vector<Row>& rows, const std::string& scene, const std::string& method,
                    double tol) {
    for (const Row& r : rows)
        if (r.scene == scene && r.method == method && std::abs(r.tolerance_px - tol) < 1e-12) return &r;
    return nullptr;
}

/// Writes the data and script and runs gnuplot. Returns a sentence for accuracy.md.
std::string plot(const Options& o, const std::vector<Row>& rows, const FamilyResults& families) {
    const std::filesystem::path dat = o.out_dir / "speed_vs_error.dat";
    const std::filesystem::path gp = o.out_dir / "speed_vs_error.gp";
    const std::filesystem::path png = o.out_dir / "speed_vs_error.png";
    struct Panel {
        std::string scene, title, xlabel;
        bool twist;
        std::vector<std::string> methods;
    };
    const std::vector<std::string> splines = {"linear", "uniform", "centripetal",      "chordal",
                                              "c2",     "auto",    "curvature_tension"};
    const std::vector<Panel> panels = {
        {"catenary", "catenary 20 m, 16 nodes", "max world error against the exact catenary (m)", false,
         splines},
        {"random_walk", "smooth random curve, 40 nodes", "max world error against the exact curve (m)", false,
         splines},
        {"helix",
         "helix, 3 turns: frame methods",
         "max twist error against the RMF (degrees)",
         true,
         {"centripetal", "centripetal+rotation", "centripetal+projection"}},
    };
    std::string data, script;
    const std::string family_panel = family_plot_panel(o.out_dir / "families.dat", families);
    script += family_panel.empty() ? "set terminal png size 1800,620 font \",11\" noenhanced\n"
                                   : "set terminal png size 1800,1240 font \",11\" noenhanced\n";
    script +=
        "set output '" + png.string() +
        "'\nset multiplot layout " + (family_panel.empty() ? "1,3" : "2,2") + " title \"wiretool bench: time per wire "
        "against error, one marker per LOD tolerance (0.1, 0.25, 0.5, 1, 2 px; larger tolerance = fewer rings"
        " = less time)\"\n";
    script +=
        "set logscale xy\nset grid\nset key top right font \",9\"\nset ylabel \"CPU time per wire, "
        "curve+lod+rings+mesh (us)\"\n";
    int block = 0;
    bool any = false;
    for (const Panel& p : panels) {
        std::string plots;
        for (const std::string& m : p.methods) {
            std::string lines;
            for (double tol : kTolerancesPx) {
                const Row* r = find_row(rows, p.scene, m, tol);
                if (!r) continue;
                const double x = std::max(p.twist ? r->twist_deg : r->world_m, 1e-12);
                lines += num(x, 6) + " " + num(r->us_cpu, 6) + " " + num(tol) + "\n";
            }
            if (lines.empty()) continue;
            data += "# " + p.scene + " " + m + "\n" + lines + "\n\n";
            plots += std::string(plots.empty() ? "plot " : ", ") + "'" + dat.string() + "' index " +
                     std::to_string(block++) + " using 1:2 with linespoints pointsize 1.3 title \"" + m +
                     "\"";
            if (m == "centripetal")
                plots += ", '' index " + std::to_string(block - 1) +
                         " using 1:2:(sprintf(\"%g px\",$3)) with labels offset 0,-1 font \",8\" notitle";
        }
        if (plots.empty()) {
            script += "set multiplot next\n";  // nothing for this panel (scene not selected)
            continue;
        }
        any = true;
        script += "set title \"" + p.title + "\"\nset xlabel \"" + p.xlabel + "\"\n" + plots + "\n";
    }
    script += family_panel;
    any = any || !family_panel.empty();
    script += "unset multiplot\n";
    if (!any) return "Plot skipped: none of its scenes (catenary, random_walk, helix) was run.";
    if (!write_text(dat, data) || !write_text(gp, script)) return "Plot skipped: cannot write its data.";
    if (std::system("gnuplot --version > /dev/null 2>&1") != 0)
        return "Plot skipped: gnuplot is not installed (tools/setup.sh installs gnuplot-nox); data and "
               "script are in "
               "speed_vs_error.dat/.gp.";
    const std::string cmd =
        "gnuplot '" + gp.string() + "' > '" + (o.out_dir / "gnuplot.log").string() + "' 2>&1";
    if (std::system(cmd.c_str()) != 0 || !std::filesystem::exists(png))
        return "Plot failed: see gnuplot.log (script speed_vs_error.gp).";
    return "Plot: speed_vs_error.png (data speed_vs_error.dat, script speed_vs_error.gp).";
}

}  // namespace

int run_accuracy_bench(const Options& o) {
    const FamilyResults families = run_family_accuracy(o);
    std::vector<Scene> scenes;
    auto want = [&](const std::string& n) { return selected(o, n); };
    if (want("catenary")) scenes.push_back(catenary_scene("catenary"));
    if (want("helix")) scenes.push_back(helix_scene());
    if (want("stretched_bend")) scenes.push_back(stretched_bend_scene());
    if (want("hairpin")) scenes.push_back(hairpin_scene());
    if (want("random_walk")) scenes.push_back(random_walk_scene());
    if (want("churn")) {
        scenes.push_back(catenary_scene("churn"));
        scenes.back().churn = true;
        scenes.back().description =
            "the 20 m catenary refined and coarsened: every 5 frames a node is inserted exactly "
            "on the curve (2 events of 3) or an inserted node removed (1 of 3)";
    }
    for (Scene& s : scenes) frame_camera(s);
    const double min_ms = o.quick ? 0.3 : 3.0;
    const int churn_frames = o.quick ? 60 : 200;
    const int pop_samples = o.quick ? kQuickPopSamplesPerSegment : kPopSamplesPerSegment;

    std::vector<Row> rows;
    for (const Scene& s : scenes) {
        std::fprintf(stderr, "bench: accuracy %s\n", s.name.c_str());
        std::map<std::string, Pops> pops;  // per curve (frame variants share their spline's)
        for (const Method& m : methods()) {
            wire::WireNodes nodes = s.nodes;
            if (m.physics) add_physics(nodes, s.stretch);
            if (s.churn) {
                const std::vector<wire::WireNodes> states = churn_states(nodes, m.spline, churn_frames);
                if (!pops.count(m.spline_key)) pops[m.spline_key] = churn_pops(states, m.spline, pop_samples);
                for (double tol : kTolerancesPx) rows.push_back(measure_churn_row(s, m, states, tol));
            } else {
                if (!pops.count(m.spline_key)) pops[m.spline_key] = event_pops(nodes, m.spline, pop_samples);
                for (double tol : kTolerancesPx) rows.push_back(measure_row(s, m, nodes, tol, min_ms));
            }
            for (std::size_t k = rows.size() - std::size(kTolerancesPx); k < rows.size(); ++k) {
                rows[k].pop_m = pops[m.spline_key].no_remedy_m;
                rows[k].pop_remedy_m = pops[m.spline_key].remedy_m;
            }
        }
    }

    Table csv;
    csv.header = {"scene",
                  "method",
                  "tolerance_px",
                  "rings",
                  "sides",
                  "vertices",
                  "bytes_cpu_mesh",
                  "bytes_gpu_rings",
                  "ns_per_vertex",
                  "us_per_wire_cpu_mesh",
                  "us_per_wire_gpu_rings",
                  "max_world_error_m",
                  "max_screen_error_px",
                  "max_twist_deg",
                  "max_pop_m",
                  "max_pop_remedy_m"};
    for (const Row& r : rows) csv.add(to_cells(r));
    if (!csv.write_csv(o.out_dir / "accuracy.csv")) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "accuracy.csv").c_str());
        return exit_failure;
    }

    const std::string plot_note = plot(o, rows, families);
    std::string md = "# wiretool bench: speed against error\n\n";
    md +=
        "One wire per scene, seen whole by a 1920x1080, 60-degree camera; every spline method (frames by "
        "double "
        "reflection) plus centripetal with the rotation and projection frame baselines; LOD tolerances 0.1, "
        "0.25, "
        "0.5, 1 and 2 px. Columns: rings, radial sides and tube vertices the LOD chose; bytes one frame "
        "uploads "
        "(cpu-mesh: vertices + indices + draw record + command; gpu-rings: 48-byte ring records + draw "
        "record + "
        "command); CPU time of curve + lod + rings + mesh (cpu-mesh) or curve + lod + rings (gpu-rings) per "
        "wire, "
        "median of 3 trials, and per vertex; `max_world_error_m`: largest distance from the drawn centre "
        "polyline "
        "to the exact curve (spline error plus tessellation error); `max_screen_error_px`: largest pixel "
        "distance "
        "from the rendered curve to the drawn polyline; `max_twist_deg`: largest angle between a ring's "
        "normal "
        "and the rotation-minimizing frame of the same curve at the same point (double reflection at 64 "
        "steps "
        "per ring interval); `max_pop_m`/`max_pop_remedy_m`: largest displacement between consecutive frames "
        "without/with the pop-free geomorph, for one node inserted exactly on the curve then one removed "
        "(churn: every event of the run). Pops do not depend on the tolerance.\n\n";
    md += "Scenes:\n\n";
    for (const Scene& s : scenes) md += "- `" + s.name + "`: " + s.description + "\n";
    md += "\n" + plot_note + "\n\n";

    // Key figures.
    md += "## Key figures (tolerance 0.5 px unless said)\n\n";
    char buf[512];
    for (const char* scene : {"catenary", "stretched_bend", "hairpin", "random_walk", "helix"}) {
        if (!find_row(rows, scene, "linear", 0.5)) continue;
        md += std::string("- `") + scene + "` world error (m) at 0.1 px:";
        for (const Method& m : methods()) {
            if (m.frames != wire::FrameMethod::double_reflection) continue;
            const Row* r = find_row(rows, scene, m.name, 0.1);
            std::snprintf(buf, sizeof buf, " %s %.3g;", m.name.c_str(), r ? r->world_m : NAN);
            md += buf;
        }
        md += "\n";
    }
    if (const Row* dr = find_row(rows, "helix", "centripetal", 0.5)) {
        const Row* rot = find_row(rows, "helix", "centripetal+rotation", 0.5);
        const Row* proj = find_row(rows, "helix", "centripetal+projection", 0.5);
        std::snprintf(buf, sizeof buf,
                      "- twist error on the helix at equal rings (%zu rings): double reflection %.3g deg, "
                      "rotation %.3g "
                      "deg (%.0fx), projection %.3g deg (%.0fx)\n",
                      dr->rings, dr->twist_deg, rot ? rot->twist_deg : NAN,
                      rot && dr->twist_deg > 0 ? rot->twist_deg / dr->twist_deg : NAN,
                      proj ? proj->twist_deg : NAN,
                      proj && dr->twist_deg > 0 ? proj->twist_deg / dr->twist_deg : NAN);
        md += buf;
    }
    for (const char* scene : {"churn", "catenary"}) {
        if (!find_row(rows, scene, "centripetal", 0.5)) continue;
        md += std::string("- `") + scene + "` largest pop, no remedy -> remedy (m):";
        for (const Method& m : methods()) {
            if (m.frames != wire::FrameMethod::double_reflection) continue;
            const Row* r = find_row(rows, scene, m.name, 0.5);
            std::snprintf(buf, sizeof buf, " %s %.3g -> %.3g;", m.name.c_str(), r->pop_m, r->pop_remedy_m);
            md += buf;
        }
        md += "\n";
    }
    md += "\n" + write_family_outputs(o, families);
    md += "\n## All rows\n\n" + csv.markdown();
    md += "\nThe DESIGN §5 hard cases: see stability.md.\n";
    if (!write_text(o.out_dir / "accuracy.md", md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "accuracy.md").c_str());
        return exit_failure;
    }
    std::fprintf(stderr, "bench: stability cases\n");
    if (!write_text(o.out_dir / "stability.md", stability_report())) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "stability.md").c_str());
        return exit_failure;
    }
    std::fprintf(stderr, "bench: %s\n", plot_note.c_str());
    return exit_ok;
}

}  // namespace wiretool::bench
