// A hanging cable as a small position-based rope simulation (Verlet integration, gravity, distance
// constraints, pinned ends) that refines and coarsens itself: nodes are inserted where the cable bends and
// removed where it runs straight, each new node with a fresh stable id and placed ON the cable's current
// rendered curve, so the wire systems' pop-free geomorph (wire/multires.hpp) makes the change invisible.
// Plain math on plain arrays: no GL, no ECS.
#pragma once

#include "wire/nodes.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace tunnel {

/// Zero means default (the value in the comment).
struct RopeSettings {
    double gravity_mps2 = 0.0;       ///< 9.81, along -y
    double damping = 0.0;            ///< velocity kept per second, 0 -> 0.35 (the rest decays)
    int substeps = 0;                ///< per step(), 0 -> 4
    int iterations = 0;              ///< constraint passes per substep, 0 -> 12
    double refine_angle_rad = 0.0;   ///< insert where consecutive elements turn more than this; 0 -> 0.30
    double coarsen_angle_rad = 0.0;  ///< remove a node whose elements (and neighbours') turn less; 0 -> 0.12
                                     ///< (merging two such elements turns < 2 * 0.12 < refine: no thrashing)
    double min_element_m = 0.0;      ///< never split an element below 2 * this; 0 -> 0.08
    double max_element_m = 0.0;      ///< never merge into an element longer than this; 0 -> 1.2
    std::size_t max_nodes = 0;       ///< 0 -> 96
    int max_changes_per_adapt = 0;   ///< insertions + removals per adapt(), 0 -> 2
};

/// What adapt() did.
struct AdaptResult {
    int inserted = 0;
    int removed = 0;
};

class Rope {
public:
    /// A rope of rest length `length_m` between `a` and `b` (both pinned) with `nodes` >= 2 nodes, laid on a
    /// parabola sagging below the chord. Ids are first_id, first_id + 1, ...
    Rope(const glm::dvec3& a, const glm::dvec3& b, double length_m, int nodes,
         const RopeSettings& settings = {});

    /// Moves every node rigidly by `delta` (e.g. the motion of the tunnel piece the rope hangs in since the
    /// last frame), velocities included: the rope then only reacts to motion relative to its piece.
    void transform(const glm::dmat4& delta);
    /// Moves the pinned ends (e.g. anchors bent by the tunnel's curved space this frame).
    void set_ends(const glm::dvec3& a, const glm::dvec3& b);
    /// Extra acceleration (m/s^2, world) at a node position, e.g. a gust of wind; empty: none.
    using AccelerationField = std::function<glm::dvec3(const glm::dvec3& position_m)>;
    /// Advances the simulation by dt_s (fixed-step callers get bit-identical results).
    void step(double dt_s, const AccelerationField& field = {});
    /// Inserts nodes where the cable bends and removes them where it is straight (at most
    /// max_changes_per_adapt changes). New nodes lie on the curve `spline` builds through the current nodes.
    AdaptResult adapt(const wire::SplineSettings& spline);

    /// positions, ids and stretch (current / rest length of the element starting at each node; the last node
    /// repeats its neighbour's value) for the wire systems.
    void write_nodes(wire::WireNodes& out) const;

    [[nodiscard]] std::size_t size() const { return x_.size(); }
    [[nodiscard]] const std::vector<glm::dvec3>& positions() const { return x_; }
    [[nodiscard]] const std::vector<uint32_t>& ids() const { return ids_; }
    [[nodiscard]] const std::vector<double>& rest_lengths() const { return rest_; }
    [[nodiscard]] double rest_length_m() const;
    /// Turning angle at interior node i (radians, 0 at the ends).
    [[nodiscard]] double turn_angle(std::size_t i) const;

private:
    void insert_after(std::size_t element, const glm::dvec3& p);
    void remove_node(std::size_t i);
    void update_masses();

    RopeSettings s_;
    std::vector<glm::dvec3> x_;     // positions
    std::vector<glm::dvec3> prev_;  // positions one substep ago (Verlet)
    std::vector<double> w_;         // inverse masses (0: pinned)
    std::vector<double> rest_;      // rest length of element i (node i to i + 1)
    std::vector<uint32_t> ids_;
    uint32_t next_id_ = 0;
};

}  // namespace tunnel
