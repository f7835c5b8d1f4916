// Catmull-Clark refinement of coarse asset meshes with OpenSubdiv Far, and the choice of the refinement level
// a bent piece needs on screen (DESIGN §4.7: low-poly meshes do not bend smoothly, paper 001's limitation).
#pragma once

#include <engine/assets/mesh_data.hpp>

#include <vector>

namespace engine::assets {

/// A coarse polygon mesh as OpenSubdiv sees it: positions welded (glTF splits a vertex per uv and per
/// normal; equal positions become one control vertex, so the surface is one piece), faces of 3 or 4 vertices
/// (quads recovered from triangle pairs), uvs face-varying, hard edges as infinitely sharp creases.
struct ControlMesh {
    std::string name;
    glm::dvec3 origin{0.0};
    std::vector<float> positions;       ///< xyz per control vertex, relative to origin
    std::vector<int> face_sizes;        ///< 3 or 4 per face
    std::vector<int> face_vertices;     ///< control vertex per face corner (counter-clockwise)
    std::vector<float> uv_values;       ///< uv per distinct value (empty if the mesh has no uvs)
    std::vector<int> face_uvs;          ///< uv value per face corner (empty if no uvs)
    std::vector<int> crease_vertices;   ///< vertex pairs of infinitely sharp edges

    [[nodiscard]] std::size_t quad_count() const;
};

/// Turns a glTF-style triangle mesh into a control mesh. Quads: two CONSECUTIVE triangles (a,b,c), (a,c,d)
/// that share an edge in opposite directions, are coplanar within 0.5 degrees and form a convex quad become
/// the quad (a,b,c,d) (the order in which authoring tools and tools/make_tunnel_assets write a quad);
/// other triangles stay triangles (Catmull-Clark accepts mixed faces). Hard edges: an edge whose two faces
/// carried different normals at its end points (the vertex was split by normal, more than 1 degree apart)
/// becomes an infinitely sharp crease. Errors (naming the mesh): no triangles, a non-finite position,
/// a degenerate triangle (repeated welded vertex), an edge used by more than two faces or twice in the same
/// direction (non-manifold or inconsistently oriented).
Status make_control_mesh(const MeshData& triangles, ControlMesh& out);

/// Highest level subdivide() accepts: a quad becomes 4^level quads.
inline constexpr int kMaxSubdivisionLevel = 6;

/// Refines uniformly `level` times with Catmull-Clark (Far::TopologyRefinerFactory<TopologyDescriptor>,
/// RefineUniform, PrimvarRefiner::Interpolate for positions and face-varying uvs). Boundary edges (the open
/// ends of a tunnel piece) stay sharp (VTX_BOUNDARY_EDGE_ONLY); uv seams interpolate linearly along the
/// seam only at corners (FVAR_LINEAR_CORNERS_ONLY). Output: triangles (each refined quad split 0-1-2,
/// 0-2-3), normals area-weighted from the refined faces, smooth across everything but creases and
/// boundaries, one output vertex per (refined vertex, uv value, smoothing group); origin and name kept.
/// Level 0 returns the control mesh triangulated. Errors (naming the mesh): level outside
/// [0, kMaxSubdivisionLevel], bad control mesh (see make_control_mesh), OpenSubdiv failing (its message).
Status subdivide(const ControlMesh& coarse, int level, MeshData& out);

/// make_control_mesh + subdivide.
Status subdivide(const MeshData& coarse_triangles, int level, MeshData& out);

/// What the level choice needs to know about a coarse piece; compute once per piece, it does not change
/// with the bend or the view. Lengths in metres in the piece's own (unbent) space, whose +z axis is the
/// bend axis of curved_space.
struct RefinementErrorModel {
    double shape_error_m = 0.0;      ///< max over smooth interior edges of w * theta / 6 (see below)
    double max_axial_extent_m = 0.0; ///< max z extent of a face: the coarse edge length the bend curves
    double max_radius_m = 0.0;       ///< max distance of a vertex from the z axis
};

/// Smooth interior edges only: creases and boundaries stay straight under refinement. For an edge between
/// faces turning by theta (radians) whose faces are w wide (longest edge of the two), a cubic B-spline
/// control polygon lies up to w * theta / 6 from its limit (a circle of N segments: r (2 pi / N)^2 / 6).
[[nodiscard]] RefinementErrorModel refinement_error_model(const ControlMesh& coarse);

/// Predicted distance (metres) between the piece refined `level` times and then bent with curvature
/// `curvature_per_m` (curved_space, about the z axis) and the bent limit surface:
///   e(level) = (shape_error_m + kappa (1 + kappa r) h_z^2 / 8) / 4^level
/// the first term the control mesh's distance to its own limit, the second the sagitta of a straight edge of
/// axial length h_z bent into an arc on the outer side at radius r (curvature kappa / (1 - kappa x) on a
/// length h_z (1 - kappa x), x = -r). Each level halves h and theta, so the error quarters.
[[nodiscard]] double predicted_error_m(const RefinementErrorModel& model, double curvature_per_m, int level);

/// The view a piece is refined for.
struct LevelQuery {
    double curvature_per_m = 0.0;  ///< bend angle per unit length of the chain over the piece (any sign)
    double distance_m = 1.0;       ///< closest distance of the piece to the camera; <= 0 means "touching"
    double focal_px = 1000.0;      ///< (viewport height / 2) / tan(fov_y / 2)
    double tolerance_px = 0.5;     ///< allowed screen error
    int max_level = 4;             ///< clamp (the frame budget), at most kMaxSubdivisionLevel
};

/// The smallest level in [0, max_level] whose predicted error, projected at distance_m
/// (error * focal_px / distance_m), is at most tolerance_px; max_level if none is. A straight piece far
/// away gets 0; bending it or moving closer raises the level. Distances below 1 cm count as 1 cm.
[[nodiscard]] int choose_subdivision_level(const RefinementErrorModel& model, const LevelQuery& query);

/// Convenience: builds the control mesh and its error model first (returns max_level if the mesh is bad).
[[nodiscard]] int choose_subdivision_level(const MeshData& coarse, const LevelQuery& query);

}  // namespace engine::assets
