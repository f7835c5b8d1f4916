// `wiretool bench`, part 3: the hard cases of DESIGN §5 run through the wire pipeline (and the bend chain),
// as a table: what was tried, what came out, and the largest error measured for it.
#include "bench/common.hpp"

#include <curved_space/chain.hpp>
#include <wire/pipeline.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

namespace wiretool::bench {
namespace {

constexpr double kPi = std::numbers::pi;

struct Checks {
    double ortho = 0.0;          ///< largest deviation of a frame from orthonormal, right-handed
    bool finite = true;          ///< every vertex position/normal finite
    std::size_t open_edges = 0;  ///< welded mesh edges not shared by exactly two triangles
    std::size_t vertices = 0;
};

bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Checks check(const wire::WirePipeline& p) {
    Checks c;
    for (const wire::Frame& f : p.rings().frames) {
        c.ortho = std::max({c.ortho, std::abs(glm::length(f.r) - 1.0), std::abs(glm::length(f.t) - 1.0),
                            std::abs(glm::dot(f.t, f.r)), std::abs(glm::dot(f.t, f.s)),
                            std::abs(glm::dot(f.r, f.s)), glm::length(glm::cross(f.r, f.s) - f.t)});
    }
    const auto& v = p.mesh().vertices;
    c.vertices = v.size();
    for (const wire::TubeVertex& x : v) c.finite = c.finite && finite3(x.position) && finite3(x.normal);
    // Weld by exact position, then every undirected edge of a non-degenerate triangle must be used twice.
    std::map<std::tuple<float, float, float>, uint32_t> ids;
    std::vector<uint32_t> weld(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        weld[i] = ids.emplace(std::make_tuple(v[i].position.x, v[i].position.y, v[i].position.z),
                              static_cast<uint32_t>(ids.size()))
                      .first->second;
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    const auto& idx = p.mesh().indices;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const uint32_t a = weld[idx[t]], b = weld[idx[t + 1]], d = weld[idx[t + 2]];
        if (a == b || b == d || a == d) continue;
        for (auto [x, y] : {std::pair{a, b}, std::pair{b, d}, std::pair{d, a}})
            ++edges[{std::min(x, y), std::max(x, y)}];
    }
    for (const auto& [e, n] : edges) c.open_edges += n != 2;
    return c;
}

struct Case {
    std::string name, result, error, note;
};

std::string sci(double v) {
    return num(v, 3);
}

/// Runs `nodes` through the pipeline; fills result/error with the checks (or the status message).
Case run_pipeline(const std::string& name, const wire::WireNodes& nodes, wire::PipelineSettings settings = {},
                  bool weld = true) {
    Case c{name, "", "", ""};
    wire::WirePipeline p;
    const engine::Status st = p.update(nodes, settings);
    if (!st) {
        c.result = "error: " + st.message;
        c.error = "-";
        return c;
    }
    const Checks k = weld ? check(p) : Checks{};
    c.result =
        std::string(k.finite ? "ok, finite" : "NON-FINITE") + ", " + std::to_string(p.rings().rings.size()) +
        " rings" +
        (weld ? (k.open_edges == 0 ? ", watertight" : ", " + std::to_string(k.open_edges) + " open edges")
              : "");
    double ortho = 0.0;
    for (const wire::Frame& f : p.rings().frames)
        ortho = std::max({ortho, std::abs(glm::dot(f.t, f.r)), std::abs(glm::length(f.r) - 1.0),
                          glm::length(glm::cross(f.r, f.s) - f.t)});
    c.error = "orthonormality " + sci(ortho);
    if (p.rings().frame_stats.subdivided_steps > 0)
        c.note +=
            "hairpin guard split " + std::to_string(p.rings().frame_stats.subdivided_steps) + " steps. ";
    if (p.rings().fold_count > 0)
        c.note += std::to_string(p.rings().fold_count) + " rings flagged as folding. ";
    if (p.curve().node_count() != nodes.size())
        c.note += "merged " + std::to_string(nodes.size()) + " -> " + std::to_string(p.curve().node_count()) +
                  " nodes. ";
    return c;
}

wire::WireNodes line_nodes(std::vector<glm::dvec3> p) {
    wire::WireNodes n;
    n.positions = std::move(p);
    return n;
}

}  // namespace

std::string stability_report() {
    std::vector<Case> cases;
    const wire::WireNodes sag = line_nodes({{0, 0, 0}, {1, -0.3, 0}, {2, -0.4, 0}, {3, -0.3, 0}, {4, 0, 0}});

    cases.push_back(
        run_pipeline("coincident nodes (exact)", line_nodes({{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {2, 1, 0}})));
    cases.push_back(run_pipeline("coincident nodes (1e-9 m apart)",
                                 line_nodes({{0, 0, 0}, {1, 0, 0}, {1 + 1e-9, 0, 0}, {2, 1, 0}})));
    {
        std::vector<glm::dvec3> p;
        for (int i = 0; i < 10; ++i) p.emplace_back(i, 0, 0);
        Case c = run_pipeline("exactly straight wire", line_nodes(p));
        wire::WirePipeline w;
        (void)w.update(line_nodes(p), {});
        double off = 0.0, spin = 0.0;
        for (std::size_t i = 0; i < w.rings().frames.size(); ++i) {
            const glm::dvec3 centre = w.rings().origin_m + w.rings().centre_m[i];
            off = std::max(off, std::hypot(centre.y, centre.z));
            spin = std::max(spin, glm::length(w.rings().frames[i].r - w.rings().frames[0].r));
        }
        c.error += ", off the line " + sci(off) + " m, normal change " + sci(spin);
        cases.push_back(c);
    }
    cases.push_back(
        run_pipeline("180-degree hairpin (tangent reverses at a node, return leg on the outbound one)",
                     line_nodes({{0, 0, 0}, {1, 0, 0}, {0, 0, 0.0}, {-1, 0.0, 0.0}})));
    cases.back().note +=
        "Open edges here count where the return leg's vertices coincide with the outbound leg's "
        "(welding by position joins the two tubes); 1 mm apart (next row) the mesh is watertight. ";
    cases.push_back(run_pipeline("180-degree hairpin (tangent reverses at a node, return leg 1 mm beside it)",
                                 line_nodes({{0, 0, 0}, {1, 0, 0}, {0, 0, 0.001}, {-1, 0.0, 0.001}})));
    cases.push_back(
        run_pipeline("tight hairpin (1 cm apart)",
                     line_nodes({{0, 0, 0}, {1, 0, 0}, {1.005, 0.005, 0}, {1, 0.01, 0}, {0, 0.01, 0}})));
    cases.push_back(run_pipeline("neighbour spacing ratio 1e6",
                                 line_nodes({{0, 0, 0}, {1e-6, 0, 0}, {1, 0.1, 0}, {2, 0, 0}})));
    {
        wire::WireNodes far = sag;
        for (glm::dvec3& p : far.positions) p += glm::dvec3(1e6, 1e6, -1e6);
        Case c = run_pipeline("coordinates 1e6 m from the origin", far);
        wire::WirePipeline a, b;
        (void)a.update(sag, {});
        (void)b.update(far, {});
        double diff = 0.0;
        for (std::size_t i = 0; i < a.rings().centre_m.size() && i < b.rings().centre_m.size(); ++i) {
            const glm::dvec3 pa = a.rings().origin_m + a.rings().centre_m[i];
            const glm::dvec3 pb = b.rings().origin_m + b.rings().centre_m[i] - glm::dvec3(1e6, 1e6, -1e6);
            diff = std::max(diff, glm::length(pa - pb));
        }
        c.error += ", ring centres vs the same wire at the origin " + sci(diff) + " m";
        cases.push_back(c);
    }
    {
        wire::PipelineSettings s;
        s.spline.radius_m = 1e-6f;
        cases.push_back(run_pipeline("radius 1e-6 m", sag, s));
        s.spline.radius_m = 0.5f;
        cases.push_back(run_pipeline("radius 0.5 m on a 0.1 m bend (larger than the curvature radius)",
                                     line_nodes({{0, 0, 0}, {1, 0, 0}, {1.1, 0.1, 0}, {1.1, 1.1, 0}}), s));
    }
    cases.push_back(run_pipeline("0 nodes", line_nodes({})));
    cases.push_back(run_pipeline("1 node", line_nodes({{0, 0, 0}})));
    cases.push_back(run_pipeline("2 nodes", line_nodes({{0, 0, 0}, {1, 0, 0}})));
    {
        wire::PipelineSettings s;
        s.spline.closed = true;
        Case c =
            run_pipeline("closed loop of 3 nodes", line_nodes({{0, 0, 0}, {1, 0, 0}, {0.5, 0.8, 0.2}}), s);
        wire::WirePipeline w;
        (void)w.update(line_nodes({{0, 0, 0}, {1, 0, 0}, {0.5, 0.8, 0.2}}), s);
        c.note += "holonomy " + sci(w.rings().frame_stats.holonomy_rad * 180.0 / kPi) +
                  " deg, spread along the loop. ";
        cases.push_back(c);
    }
    {
        wire::WireNodes walk;
        glm::dvec3 p(0.0), dir(1.0, 0.0, 0.0);
        unsigned seed = 7;
        auto rnd = [&seed] {
            seed = seed * 1664525u + 1013904223u;
            return (seed >> 8) * (1.0 / 16777216.0) - 0.5;
        };
        for (int i = 0; i < 100000; ++i) {
            dir = glm::normalize(dir + 0.1 * glm::dvec3(rnd(), rnd(), rnd()));
            p += 0.01 * dir;
            walk.positions.push_back(p);
        }
        wire::PipelineSettings s;
        s.tessellate.rings_per_segment = 2;
        s.tube.sides = 6;
        const double t0 = wall_ms();
        Case c = run_pipeline("100,000-node wire (random walk)", walk, s, false);
        c.note +=
            "curve + rings + mesh in " + num(wall_ms() - t0, 3) + " ms wall (2 rings/segment, 6 sides). ";
        cases.push_back(c);
    }
    {
        wire::WireNodes bad = sag;
        bad.positions[2].y = std::numeric_limits<double>::quiet_NaN();
        cases.push_back(run_pipeline("NaN in a node", bad));
        bad = sag;
        bad.positions[3].z = std::numeric_limits<double>::infinity();
        cases.push_back(run_pipeline("Inf in a node", bad));
    }
    // Bend chain (curved space): alpha = 0, alpha -> 0, and 1,000 segments closing a circle.
    for (double alpha : {0.0, 1e-12}) {
        Case c{alpha == 0.0 ? "bend with alpha = 0" : "bend with alpha = 1e-12 (alpha -> 0)", "", "", ""};
        curved_space::Chain chain;
        const std::vector<curved_space::Segment> segs{
            {.length_m = 4.0, .angle_rad = alpha, .direction_rad = 0.3}};
        const engine::Status st = curved_space::make_chain(segs, chain);
        if (!st) {
            c.result = "error: " + st.message;
        } else {
            double err = 0.0;
            bool finite = true;
            for (int i = 0; i <= 40; ++i) {
                const glm::dvec3 q(0.2 * std::sin(i), 0.1 * std::cos(i), 0.1 * i);
                const glm::dvec3 b = chain.transform_point(q);
                finite = finite && std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z);
                err = std::max(err, glm::length(b - q));  // straight (alpha = 0) or bent by ~alpha * z^2
            }
            c.result = finite ? "ok, finite" : "NON-FINITE";
            c.error = "distance from the unbent point " + sci(err) + " m";
        }
        cases.push_back(c);
    }
    {
        Case c{"1,000 chained bend segments closing a full circle", "", "", ""};
        std::vector<curved_space::Segment> segs(1000, {.length_m = 0.01, .angle_rad = 2.0 * kPi / 1000.0});
        curved_space::Chain chain;
        const engine::Status st = curved_space::make_chain(segs, chain);
        if (!st) {
            c.result = "error: " + st.message;
        } else {
            const glm::dvec3 end = chain.transform_point({0.0, 0.0, chain.total_length_m()});
            c.result = "ok";
            c.error = "closure gap " + sci(glm::length(end)) + " m (circle radius " +
                      num(10.0 / (2.0 * kPi), 4) + " m)";
        }
        cases.push_back(c);
    }

    std::string md =
        "# wiretool bench: stability (DESIGN §5 hard cases)\n\n"
        "Each case runs through wire::WirePipeline (centripetal spline, 8 rings per segment, 8 sides, "
        "caps; frames by double reflection) or the curved-space bend chain. `result`: the status "
        "message for rejected input, else finiteness, ring count and whether the welded mesh is "
        "watertight (every edge shared by two triangles); `max error`: frame orthonormality (largest "
        "|t.r|, ||r|-1|, |r x s - t|) plus the case's own measure.\n\n"
        "| case | result | max error | note |\n| --- | --- | --- | --- |\n";
    for (const Case& c : cases)
        md += "| " + c.name + " | " + c.result + " | " + c.error + " | " + c.note + " |\n";
    return md;
}

}  // namespace wiretool::bench
