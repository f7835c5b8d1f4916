// A hanging cable as a small position-based rope simulation (Verlet integration, gravity, distance
// constraints, a bending constraint per interior node, contacts with friction, pinned ends) that refines and
// coarsens itself: nodes are inserted where the cable bends and
// removed where it runs straight, each new node with a fresh stable id and placed ON the cable's current
// rendered curve, so the wire systems' pop-free blend (wire/pop_free.hpp) makes the change invisible.
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
    double refine_angle_rad = 0.0;   ///< insert where consecutive elements turn more than this; 0 -> 0.17
    double coarsen_angle_rad = 0.0;  ///< remove a node whose elements (and neighbours') turn less; 0 -> 0.07
                                     ///< (merging two such elements turns < 2 * 0.07 < refine: no thrashing)
    double bend_stiffness = 0.0;     ///< fraction of a node's offset from the straight line through its
                                     ///< neighbours removed per constraint pass (resists bending); 0 -> 0.04
    double max_turn_rad = 0.0;       ///< hard limit of the turn at a node (a stiff cable cannot kink when
                                     ///< refinement is out of nodes); 0 -> 0.24 (14 deg)
    double friction = 0.0;           ///< Coulomb coefficient of the contacts (static = kinetic); 0 -> 0.7
    double radius_m = 0.0;           ///< tube radius the contacts keep clear; 0 -> 0.02
    double min_element_m = 0.0;      ///< never split an element below 2 * this; 0 -> 0.05
    double max_element_m = 0.0;      ///< never merge into an element longer than this; 0 -> 1.2
    std::size_t max_nodes = 0;       ///< 0 -> 96
    int max_changes_per_adapt = 0;   ///< insertions + removals per adapt(), 0 -> 2
};

/// What adapt() did.
struct AdaptResult {
    int inserted = 0;
    int removed = 0;
};

/// The deepest contact of a rope element (the segment a..b, a tube of radius r) with the obstacles, in the
/// space the rope is simulated in: where along the element (t in [0, 1]), the unit normal pointing out of the
/// obstacle and the depth (metres along the normal the element must move to clear it; > 0 when touching).
struct ElementContact {
    double t = 0.0;
    glm::dvec3 normal{0.0, 1.0, 0.0};
    double depth_m = 0.0;
};
/// Returns true and fills `out` when the element touches an obstacle.
using Collider =
    std::function<bool(const glm::dvec3& a, const glm::dvec3& b, double radius_m, ElementContact& out)>;

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
    /// Advances the simulation by dt_s (fixed-step callers get bit-identical results): substeps of
    /// begin_substep(), iterations of solve(), end_substep(). `collider` (may be empty) keeps the tube out of
    /// obstacles, with friction.
    void step(double dt_s, const AccelerationField& field = {}, const Collider& collider = {});
    /// The pieces of step(), for callers that solve several ropes together (rope-rope contacts between the
    /// iterations): Verlet prediction over h_s seconds, one constraint pass (distance, bending, contacts),
    /// and the friction of the substep's contacts.
    void begin_substep(double h_s, const AccelerationField& field = {});
    void solve(int iteration, const Collider& collider = {});
    void end_substep();
    /// Pushes element ea of `a` and element eb of `b` apart along `normal` (from b to a) by `depth_m`, split
    /// by inverse mass; the contact counts for both ropes' friction. sa, sb: where along the elements.
    static void separate(Rope& a, std::size_t ea, double sa, Rope& b, std::size_t eb, double sb,
                         const glm::dvec3& normal, double depth_m);
    [[nodiscard]] const RopeSettings& settings() const { return s_; }
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
    void push_element(std::size_t e, double t, const glm::dvec3& normal, double depth_m);
    void bend(double stiffness, bool backward);
    void friction();

    RopeSettings s_;
    std::vector<glm::dvec3> x_;        // positions
    std::vector<glm::dvec3> prev_;     // positions one substep ago (Verlet)
    std::vector<double> w_;            // inverse masses (0: pinned)
    std::vector<double> rest_;         // rest length of element i (node i to i + 1)
    std::vector<glm::dvec3> contact_;  // per node: sum of the contact pushes of the substep (friction)
    std::vector<uint32_t> ids_;
    uint32_t next_id_ = 0;
};

}  // namespace tunnel
