// Test harness (wire::render_testing, never installed): the nodes path's ring pass driven alone, its LOD and rings
// programs (shaders.hpp). From the segments a GpuCurvePass built, two compute dispatches (the counts and ring
// ranges, then the rings) write every wire's ring records (wire::PackedRing, the 28-byte form the ring vertex
// shader reads), one invocation per wire walking its rings in order, as wire::place_rings + wire::build_rings do
// on the CPU, which stays the reference (tests/modules/wire/render/gpu_curves_test.cpp compares the two):
//
//   pass->build(wires);                        // GpuCurvePass: the segments
//   auto rings = wire::render::GpuRingPass::create();
//   rings->build(*pass, jobs);                 // per wire: rings per segment, the carried first normal
//   rings->read(out);                          // (tests, tools) the records back
//
// What it computes, per ring (place_rings' placement from the per-segment counts, build_rings' quantities):
// - centre and unit tangent from the segment (unit_tangent()'s one-sided limits where the derivative vanishes);
// - the frame by double reflection (Wang et al. 2008) from the first normal (the carried previous normal
//   projected onto the first tangent, else seed_normal(); on the nodes path the previous normal is the one the
//   GPU kept, turned by the header's rotation: the wire's motion fitted on the CPU, motion.hpp), through the start of every segment an interval crosses,
//   with compute_frames' hairpin guard (a step with an ill-conditioned second reflection or a turn over 45 degrees
//   is bisected, at most 10 deep; an explicit stack stands in for the recursion) and, on closed loops, the
//   holonomy spread over arc length (the loop is walked twice: first for the twist, then to write);
// - radius by the monotone Hermite of the node radii (radius_at()), texture u by 3-point Gauss-Legendre of
//   |B'| / (2 pi R stretch) per ring interval, summed in double (one double add per ring).
// Precision: float arithmetic on the segments' difference form (GpuCurvePass keeps b0 and the differences of the
// control points), so derivatives, chords between rings and arc lengths keep float precision relative to a
// segment, not to the wire's extent; centres are float offsets from the wire's origin (as the CPU's Ring).
// The counts: the caller's (place_rings' rule), or the screen-space LOD's (wire/lod.hpp's per-segment evaluation:
// Wang's count at each segment's nearest hull depth and off-axis factor, coarse off-screen segments, the side count,
// strips and lines, hysteresis on counts and sides kept on the GPU between builds of the same wires; below the node
// resolution unless LodSettings::keep_node_resolution, the span hierarchy built per wire as the segments are
// visited and decided as update_lod decides it). A wire's rings get a range of the ring buffer by an atomic counter (no scan).
// The renderer's nodes path (src/node_path.cpp) runs the same programs with the commands program between them (LOD,
// the indirect commands, the rings with their draw and chunk records) and draws a wire that does not fit the ring
// buffer with one ring a segment from a reserve.
#pragma once

#include "wire/lod.hpp"
#include "wire/packed_ring.hpp"
#include "wire/render/testing/gpu_curve_pass.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace wire::render {

/// One wire's ring request, for the wire of the same index in the curve pass's last build.
struct GpuRingJob {
    /// Without the LOD: rings per segment, place_rings' rule (segment 0 gets at least 1). With it: unused.
    std::span<const uint32_t> counts;
    bool has_previous_normal = false;  ///< FrameSettings::has_previous_normal
    glm::vec3 previous_normal{};       ///< FrameSettings::previous_normal (world direction)
    /// With the LOD: forget this wire's previous counts and sides (update_lod on a fresh WireLod). They are also
    /// forgotten when the build's wires or segment counts differ from the last build's.
    bool restart_lod = false;
    /// The nodes path's carry: the previous normal is this wire's ring 0 normal of the last build (kept on the GPU
    /// while the build has as many wires), turned by its GpuCurveWire::motion; has_previous_normal and
    /// previous_normal are then not read. A wire without a last build is seeded.
    bool carry_last = false;
};

/// The LOD a build evaluates on the GPU.
struct GpuLodFrame {
    LodView view{};
    /// As update_lod reads them (keep_node_resolution off: spans below the node resolution).
    LodSettings settings{};
    /// Ring records the build may write; 0: every segment at max_rings_per_segment (always enough). A wire that
    /// does not fit is not written (GpuRingResult::overflow).
    std::size_t ring_capacity = 0;
};

/// One wire's rings read back.
struct GpuRingResult {
    std::vector<PackedRing> rings;  ///< centres relative to the curve pass's origin of the wire; empty if culled
    std::vector<uint32_t> counts;   ///< rings per segment (the LOD's, or the caller's)
    uint32_t sides = 0, drawn_sides = 0;  ///< with the LOD: WireLod::sides, drawn_sides (0 if culled)
    bool visible = true;            ///< with the LOD: WireLod::visible
    bool overflow = false;          ///< the ring buffer was full: nothing written
    float radius_px = 0.0f;         ///< with the LOD: WireLod::radius_px
    glm::vec3 first_normal{};       ///< ring 0's normal r (the next frame's previous normal)
    double u_close = 0.0;           ///< closed loops: u where the loop closes (RingSet::u.back())
    double length_m = 0.0;          ///< RingSet::length_m
    float holonomy_rad = 0.0f;      ///< closed loops: FrameStats::holonomy_rad
};

/// The ring compute pass (owns its GL programs and buffers: create, use and destroy it with the same context
/// current).
class GpuRingPass {
public:
    /// Compiles the LOD, place and rings programs. Fails (with the driver's log) without GL 4.3 compute.
    static engine::Expected<GpuRingPass> create();

    /// Every wire's rings from `curves`' last build (a dispatch of the LOD program, then the place program's ring
    /// ranges, then the rings program). jobs.size() must equal the number of wires of that build and each job's counts its wire's segment
    /// count; otherwise the call fails naming the wire.
    /// With `lod`, the counts come from the LOD on the GPU (see the file comment).
    [[nodiscard]] Status build(const GpuCurvePass& curves, std::span<const GpuRingJob> jobs,
                               const GpuLodFrame* lod = nullptr);

    /// The last build's rings, one result per wire (waits for the GPU).
    void read(std::vector<GpuRingResult>& out) const;


private:
    engine::gfx::Program lod_program_, place_program_, ring_program_;
    engine::gfx::Buffer jobs_, counts_, rings_, state_, counter_, visible_;
    std::vector<uint32_t> count_first_, segments_;  // per wire of the last build: its counts' range
    std::size_t ring_capacity_ = 0, count_total_ = 0, state_wires_ = 0;
    bool lod_ = false;
};

}  // namespace wire::render
