// Contact geometry of the hanging cables in the unbent tunnel space: the level's shapes (wall, ribs, walkway,
// wall cables) as simple solids, the deepest contact of a point or a rope element with them, and the closest
// points of two segments (rope-rope contacts). Plain math: no GL, no ECS.
#pragma once

#include "tunnel/rope.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <vector>

namespace tunnel {

/// The level geometry the ropes collide with, in the unbent tunnel space (z along the chain, piece k covers
/// [k * piece_length_m, (k + 1) * piece_length_m)), measured from the refined meshes at the highest cached
/// level.
struct LevelShapes {
    double piece_length_m = 4.0;      ///< the ribs repeat every piece
    double wall_radius_m = 0.0;       ///< the wall's inner surface (smallest distance from the axis)
    double rib_inner_radius_m = 0.0;  ///< the ribs' inner faces
    std::vector<glm::dvec2> rib_z_m;  ///< z range of each rib within a piece
    glm::dvec2 walkway_min_m{0.0};    ///< walkway cross-section box (x, y), all along z
    glm::dvec2 walkway_max_m{0.0};
    struct Cable {
        glm::dvec2 section_m{0.0};
        double radius_m = 0.0;
    };
    std::vector<Cable> cables;  ///< the fixed wall cables
};

/// Closest points of segments p0-p1 and q0-q1: parameters s, t in [0, 1].
void closest_segments(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& q0, const glm::dvec3& q1,
                      double& s, double& t);

/// Length, in the bent space, of a unit step along the unbent direction n where the bend stretches z by
/// z_scale (the cross-section is carried rigidly): a tube of radius r needs r / metric unbent clearance.
double bent_metric(const glm::dvec3& n, double z_scale);

/// The deepest contact of point p with the shapes of a tunnel total_z long: signed distance (negative
/// inside) and outward normal, unbent. Returns false when nothing is within `reach` of the point.
bool point_contact(const LevelShapes& g, double total_z, const glm::dvec3& p, double reach, double& distance,
                   glm::dvec3& normal);

/// The deepest contact of the element a-b (a tube of radius r) with the shapes; `z_scale` is the bend's
/// smallest stretch of z over the element's piece (bent_metric). Returns false when the tube touches nothing.
bool element_contact(const LevelShapes& g, double total_z, const glm::dvec3& a, const glm::dvec3& b, double r,
                     double z_scale, ElementContact& out);

}  // namespace tunnel
