// Rope simulation with adaptive node count: see rope.hpp.
#include "tunnel/rope.hpp"

#include "wire/curve.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>

namespace tunnel {

namespace {

// Largest length ratio of neighbouring elements that adapt() leaves (and creates).
constexpr double kGrading = 2.0;

RopeSettings with_defaults(RopeSettings s) {
    if (s.gravity_mps2 == 0.0) s.gravity_mps2 = 9.81;
    if (s.damping == 0.0) s.damping = 0.35;
    if (s.substeps == 0) s.substeps = 4;
    if (s.iterations == 0) s.iterations = 12;
    if (s.refine_angle_rad == 0.0) s.refine_angle_rad = 0.17;
    if (s.coarsen_angle_rad == 0.0) s.coarsen_angle_rad = 0.07;
    if (s.bend_stiffness == 0.0) s.bend_stiffness = 0.04;
    if (s.max_turn_rad == 0.0) s.max_turn_rad = 0.24;
    if (s.friction == 0.0) s.friction = 0.7;
    if (s.radius_m == 0.0) s.radius_m = 0.02;
    if (s.min_element_m == 0.0) s.min_element_m = 0.05;
    if (s.max_element_m == 0.0) s.max_element_m = 1.2;
    if (s.max_nodes == 0) s.max_nodes = 96;
    if (s.max_changes_per_adapt == 0) s.max_changes_per_adapt = 2;
    return s;
}

}  // namespace

Rope::Rope(const glm::dvec3& a, const glm::dvec3& b, double length_m, int nodes, const RopeSettings& settings)
    : s_(with_defaults(settings)) {
    assert(nodes >= 2 && "a rope needs two nodes");
    const double chord = glm::length(b - a);
    // Parabola of the same length: L ~ c + 8 h^2 / (3 c).
    const double sag = chord > 0.0 ? std::sqrt(std::max(0.0, 3.0 * chord * (length_m - chord) / 8.0)) : 0.0;
    for (int i = 0; i < nodes; ++i) {
        const double t = static_cast<double>(i) / (nodes - 1);
        glm::dvec3 p = a + t * (b - a);
        p.y -= 4.0 * sag * t * (1.0 - t);
        x_.push_back(p);
        ids_.push_back(next_id_++);
    }
    prev_ = x_;
    rest_.assign(static_cast<std::size_t>(nodes - 1), length_m / (nodes - 1));
    update_masses();
}

double Rope::rest_length_m() const {
    double sum = 0.0;
    for (double r : rest_) sum += r;
    return sum;
}

void Rope::update_masses() {
    // Mass follows the rope length a node stands for, so refinement does not move the mass around.
    const std::size_t n = x_.size();
    w_.assign(n, 0.0);
    for (std::size_t i = 1; i + 1 < n; ++i) w_[i] = 1.0 / (0.5 * (rest_[i - 1] + rest_[i]));
}

void Rope::transform(const glm::dmat4& delta) {
    for (glm::dvec3& p : x_) p = glm::dvec3(delta * glm::dvec4(p, 1.0));
    for (glm::dvec3& p : prev_) p = glm::dvec3(delta * glm::dvec4(p, 1.0));
}

void Rope::set_ends(const glm::dvec3& a, const glm::dvec3& b) {
    x_.front() = a;
    x_.back() = b;
    prev_.front() = a;
    prev_.back() = b;
}

void Rope::step(double dt_s, const AccelerationField& field, const Collider& collider) {
    if (dt_s <= 0.0) return;
    const double h = dt_s / s_.substeps;
    for (int sub = 0; sub < s_.substeps; ++sub) {
        begin_substep(h, field);
        for (int it = 0; it < s_.iterations; ++it) solve(it, collider);
        end_substep();
    }
}

void Rope::begin_substep(double h, const AccelerationField& field) {
    const double keep = std::pow(s_.damping, h);
    const glm::dvec3 g(0.0, -s_.gravity_mps2 * h * h, 0.0);
    const std::size_t n = x_.size();
    contact_.assign(n, glm::dvec3(0.0));
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const glm::dvec3 v = (x_[i] - prev_[i]) * keep;
        prev_[i] = x_[i];
        x_[i] += v + g;
        if (field) x_[i] += field(prev_[i]) * (h * h);
    }
}

void Rope::push_element(std::size_t e, double t, const glm::dvec3& normal, double depth_m) {
    // A point constraint on the element: the point at t moves by depth along the normal, the two nodes by
    // their share (inverse mass times barycentric weight).
    const double wa = w_[e] * (1.0 - t);
    const double wb = w_[e + 1] * t;
    const double denom = wa * (1.0 - t) + wb * t;
    if (denom <= 0.0) return;
    const double lambda = depth_m / denom;
    x_[e] += (wa * lambda) * normal;
    x_[e + 1] += (wb * lambda) * normal;
    contact_[e] += (wa * lambda) * normal;
    contact_[e + 1] += (wb * lambda) * normal;
}

void Rope::solve(int it, const Collider& collider) {
    const std::size_t n = x_.size();
    if (contact_.size() != n) contact_.assign(n, glm::dvec3(0.0));
    // Distances; alternate the sweep direction so neither end is favoured.
    for (std::size_t k = 0; k + 1 < n; ++k) {
        const std::size_t e = (it % 2 == 0) ? k : n - 2 - k;
        const glm::dvec3 d = x_[e + 1] - x_[e];
        const double len = glm::length(d);
        const double wsum = w_[e] + w_[e + 1];
        if (len < 1e-12 || wsum == 0.0) continue;
        const glm::dvec3 corr = d * ((len - rest_[e]) / (len * wsum));
        x_[e] += w_[e] * corr;
        x_[e + 1] -= w_[e + 1] * corr;
    }
    // Contacts every other pass and on the last (the distance pass between them barely moves a node).
    if (collider && (it % 2 == 1 || it + 1 == s_.iterations)) {
        ElementContact c;
        for (std::size_t e = 0; e + 1 < n; ++e)
            if (collider(x_[e], x_[e + 1], s_.radius_m, c) && c.depth_m > 0.0)
                push_element(e, c.t, c.normal, c.depth_m);
        friction();  // inside the passes too: the distance constraints must not drag a resting node along
    }
    // Bending last, on the passes with contacts: the largest turn holds at the end of them (contacts pull it
    // back next time); twice the stiffness on half the passes.
    if (it % 2 == 1 || it + 1 == s_.iterations) bend(2.0 * s_.bend_stiffness, it % 4 == 1);
}

void Rope::bend(double stiffness, bool backward) {
    // Node i's offset h from the chord of its neighbours (at the split of the rest lengths) shrinks by the
    // stiffness, and never exceeds the offset of the largest allowed turn, l1 l2 sin(max) / chord.
    const std::size_t n = x_.size();
    const double sin_max = std::sin(s_.max_turn_rad);
    for (std::size_t k = 1; k + 1 < n; ++k) {
        const std::size_t i = backward ? n - 1 - k : k;
        const double l1 = rest_[i - 1];
        const double l2 = rest_[i];
        const double f = l1 / (l1 + l2);
        const glm::dvec3 chord = x_[i + 1] - x_[i - 1];
        const glm::dvec3 off = x_[i] - (x_[i - 1] + f * chord);
        const double h = glm::length(off);
        if (h < 1e-12) continue;
        const double chord_len = std::max(glm::length(chord), 1e-9);
        const double h_max =
            glm::length(x_[i] - x_[i - 1]) * glm::length(x_[i + 1] - x_[i]) * sin_max / chord_len;
        const double target = std::min(h * (1.0 - stiffness), h_max);
        const double c = h - target;
        const double denom = w_[i] + w_[i - 1] * (1.0 - f) * (1.0 - f) + w_[i + 1] * f * f;
        if (c <= 0.0 || denom <= 0.0) continue;
        const glm::dvec3 nrm = off / h;
        const double lambda = c / denom;
        x_[i] -= (w_[i] * lambda) * nrm;
        x_[i - 1] += (w_[i - 1] * (1.0 - f) * lambda) * nrm;
        x_[i + 1] += (w_[i + 1] * f * lambda) * nrm;
    }
}

void Rope::end_substep() {
    friction();
    // A few passes of the turn limit alone: Gauss-Seidel sweeps of neighbouring nodes undo each other, and a
    // contact may have pressed a kink in last.
    for (int pass = 0; pass < 4; ++pass) bend(0.0, pass % 2 == 1);
}

void Rope::friction() {
    // Coulomb friction on the substep's contacts: the motion along the contact plane is cancelled up to
    // friction times the normal push (static), reduced by it beyond (kinetic). A rope draped over a rib
    // stays.
    const std::size_t n = x_.size();
    for (std::size_t i = 1; i + 1 < n && i < contact_.size(); ++i) {
        const double push = glm::length(contact_[i]);
        if (push < 1e-12) continue;
        const glm::dvec3 nrm = contact_[i] / push;
        const glm::dvec3 motion = x_[i] - prev_[i];
        const glm::dvec3 tangential = motion - glm::dot(motion, nrm) * nrm;
        const double t = glm::length(tangential);
        if (t < 1e-15) continue;
        x_[i] -= tangential * std::min(1.0, s_.friction * push / t);
    }
}

void Rope::separate(Rope& a, std::size_t ea, double sa, Rope& b, std::size_t eb, double sb,
                    const glm::dvec3& normal, double depth_m) {
    const double wa = a.w_[ea] * (1.0 - sa) * (1.0 - sa) + a.w_[ea + 1] * sa * sa;
    const double wb = b.w_[eb] * (1.0 - sb) * (1.0 - sb) + b.w_[eb + 1] * sb * sb;
    const double wsum = wa + wb;
    if (wsum <= 0.0 || depth_m <= 0.0) return;
    // Each side moves its point by its share of the depth; push_element spreads it over the element's nodes.
    if (wa > 0.0) a.push_element(ea, sa, normal, depth_m * wa / wsum);
    if (wb > 0.0) b.push_element(eb, sb, -normal, depth_m * wb / wsum);
}

double Rope::turn_angle(std::size_t i) const {
    if (i == 0 || i + 1 >= x_.size()) return 0.0;
    const glm::dvec3 a = x_[i] - x_[i - 1];
    const glm::dvec3 b = x_[i + 1] - x_[i];
    const double la = glm::length(a);
    const double lb = glm::length(b);
    if (la < 1e-12 || lb < 1e-12) return 0.0;
    return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

void Rope::insert_after(std::size_t e, const glm::dvec3& p) {
    const double da = glm::length(p - x_[e]);
    const double db = glm::length(x_[e + 1] - p);
    const double f = (da + db) > 0.0 ? da / (da + db) : 0.5;
    // The new node moves with its neighbours (Verlet velocity is x - prev).
    const glm::dvec3 v = (1.0 - f) * (x_[e] - prev_[e]) + f * (x_[e + 1] - prev_[e + 1]);
    const double r = rest_[e];
    x_.insert(x_.begin() + static_cast<std::ptrdiff_t>(e + 1), p);
    prev_.insert(prev_.begin() + static_cast<std::ptrdiff_t>(e + 1), p - v);
    ids_.insert(ids_.begin() + static_cast<std::ptrdiff_t>(e + 1), next_id_++);
    contact_.assign(x_.size(), glm::dvec3(0.0));
    rest_[e] = r * f;
    rest_.insert(rest_.begin() + static_cast<std::ptrdiff_t>(e + 1), r * (1.0 - f));
    update_masses();
}

void Rope::remove_node(std::size_t i) {
    assert(i > 0 && i + 1 < x_.size());
    rest_[i - 1] += rest_[i];
    rest_.erase(rest_.begin() + static_cast<std::ptrdiff_t>(i));
    x_.erase(x_.begin() + static_cast<std::ptrdiff_t>(i));
    prev_.erase(prev_.begin() + static_cast<std::ptrdiff_t>(i));
    ids_.erase(ids_.begin() + static_cast<std::ptrdiff_t>(i));
    contact_.assign(x_.size(), glm::dvec3(0.0));
    update_masses();
}

AdaptResult Rope::adapt(const wire::SplineSettings& spline) {
    AdaptResult result;
    for (int change = 0; change < s_.max_changes_per_adapt; ++change) {
        const std::size_t n = x_.size();
        // Refine: the sharpest turn above the threshold, split its longer element on the current curve.
        std::size_t sharpest = 0;
        double sharpest_angle = s_.refine_angle_rad;
        for (std::size_t i = 1; i + 1 < n; ++i) {
            const double a = turn_angle(i);
            const std::size_t e = rest_[i - 1] >= rest_[i] ? i - 1 : i;
            if (a > sharpest_angle && rest_[e] >= 2.0 * s_.min_element_m) {
                sharpest_angle = a;
                sharpest = i;
            }
        }
        // Grading: an element more than kGrading times as long as a neighbour is split too (a spline through
        // a long element next to short ones overshoots into a loop).
        std::size_t graded = n;
        for (std::size_t e = 0; e + 1 < n && sharpest == 0; ++e) {
            const double shortest = std::min(e > 0 ? rest_[e - 1] : 1e30, e + 2 < n ? rest_[e + 1] : 1e30);
            if (rest_[e] > kGrading * shortest && rest_[e] >= 2.0 * s_.min_element_m &&
                (graded == n || rest_[e] > rest_[graded]))
                graded = e;
        }
        if ((sharpest != 0 || graded < n) && n < s_.max_nodes) {
            const std::size_t e = sharpest == 0                            ? graded
                                  : rest_[sharpest - 1] >= rest_[sharpest] ? sharpest - 1
                                                                           : sharpest;
            glm::dvec3 p = 0.5 * (x_[e] + x_[e + 1]);
            wire::WireNodes nodes;
            write_nodes(nodes);
            wire::Curve curve;
            if (wire::build_curve(nodes, spline, curve).ok()) {
                for (std::size_t k = 0; k + 1 < curve.node_count(); ++k) {
                    if (curve.source_node[k] == e && curve.source_node[k + 1] == e + 1) {
                        p = wire::position(curve.segments[k], 0.5);
                        break;
                    }
                }
            }
            insert_after(e, p);
            ++result.inserted;
            continue;
        }
        // Coarsen: the straightest node whose neighbourhood is straight and whose merged element stays short.
        std::size_t straightest = 0;
        double straightest_angle = s_.coarsen_angle_rad;
        for (std::size_t i = 1; i + 1 < n && n > 3; ++i) {
            const double a = std::max({turn_angle(i - 1), turn_angle(i), turn_angle(i + 1)});
            const double merged = rest_[i - 1] + rest_[i];
            const double shortest = std::min(i >= 2 ? rest_[i - 2] : 1e30, i + 2 < n ? rest_[i + 1] : 1e30);
            if (a < straightest_angle && merged <= s_.max_element_m && merged <= kGrading * shortest) {
                straightest_angle = a;
                straightest = i;
            }
        }
        if (straightest == 0) break;
        remove_node(straightest);
        ++result.removed;
    }
    return result;
}

void Rope::write_nodes(wire::WireNodes& out) const {
    out = wire::WireNodes{};
    out.positions = x_;
    out.ids = ids_;
    out.stretch.resize(x_.size());
    for (std::size_t i = 0; i + 1 < x_.size(); ++i) {
        const double len = glm::length(x_[i + 1] - x_[i]);
        out.stretch[i] = static_cast<float>(std::clamp(len / rest_[i], 0.05, 20.0));
    }
    out.stretch.back() = x_.size() >= 2 ? out.stretch[x_.size() - 2] : 1.0f;
}

}  // namespace tunnel
