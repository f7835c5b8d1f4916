// The records the CPU and the GPU programs share (shaders/gpu_records.h, one text read as C++ and as GLSL), field
// by field: every offset and the array stride of each std430 record as the driver laid it out
// (glGetProgramResourceiv, GL_OFFSET and GL_TOP_LEVEL_ARRAY_STRIDE on the linked programs) against the C++
// compiler's offsetof and sizeof. The two languages align differently (a vec3, a vec4 in C++ by alignas): a field
// placed where they disagree, or a program that declares its own copy of a record, fails here by name, not as a
// wrong picture on some driver.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <cstddef>
#include <memory>
#include <string>

#include "engine/gfx/resources.hpp"
#include "engine/platform/context.hpp"
#include "gpu_wire_data.hpp"
#include "shaders.hpp"

namespace {

namespace gfx = engine::gfx;
namespace platform = engine::platform;
using namespace wire::render::detail;

class GpuLayout : public ::testing::Test {
protected:
    void SetUp() override {
        auto made = platform::create_headless_context(
            {.backend = platform::Backend::headless, .width = 16, .height = 16, .quiet = true});
        ASSERT_TRUE(made.ok()) << made.error().message;
        ctx_ = std::move(made).value();
    }
    /// GL_OFFSET (within its record) of buffer variable `name`; -1 when the program has no such variable.
    static GLint offset(const gfx::Program& p, const std::string& name) { return property(p, name, GL_OFFSET); }
    /// GL_TOP_LEVEL_ARRAY_STRIDE of the record array `name` belongs to.
    static GLint stride(const gfx::Program& p, const std::string& name) {
        return property(p, name, GL_TOP_LEVEL_ARRAY_STRIDE);
    }
    static GLint property(const gfx::Program& p, const std::string& name, GLenum what) {
        const GLuint index = glGetProgramResourceIndex(p.id(), GL_BUFFER_VARIABLE, name.c_str());
        if (index == GL_INVALID_INDEX) return -1;
        GLint value = -1;
        glGetProgramResourceiv(p.id(), GL_BUFFER_VARIABLE, index, 1, &what, 1, nullptr, &value);
        return value;
    }
    /// The draw record (GpuDraw) as `p` declares it: written by the rings program, read by the vertex shader.
    static void expect_draw_record(const gfx::Program& p);
    /// Every field of the wire header (GpuCurveHeader) in `p`'s record array `array`, and its stride.
    static void expect_header(const gfx::Program& p, const std::string& array);
    std::unique_ptr<platform::Context> ctx_;
};

#define EXPECT_FIELD(program, glsl, type, member) \
    EXPECT_EQ(offset(program, glsl), static_cast<GLint>(offsetof(type, member))) << (glsl)

void GpuLayout::expect_draw_record(const gfx::Program& p) {
    EXPECT_EQ(stride(p, "draws[0].offset_m"), static_cast<GLint>(sizeof(GpuDraw)));
    EXPECT_FIELD(p, "draws[0].offset_m", GpuDraw, offset_m);
    EXPECT_FIELD(p, "draws[0].ring_first", GpuDraw, ring_first);
    EXPECT_FIELD(p, "draws[0].ring_count", GpuDraw, ring_count);
    EXPECT_FIELD(p, "draws[0].sides", GpuDraw, sides);
    EXPECT_FIELD(p, "draws[0].flags", GpuDraw, flags);
    EXPECT_FIELD(p, "draws[0].u_close", GpuDraw, u_close);
}

void GpuLayout::expect_header(const gfx::Program& p, const std::string& array) {
    SCOPED_TRACE(array);
    const std::string at = array + "[0].";
    EXPECT_EQ(stride(p, at + "node_first"), static_cast<GLint>(sizeof(GpuCurveHeader)));
    EXPECT_FIELD(p, at + "node_first", GpuCurveHeader, node_first);
    EXPECT_FIELD(p, at + "node_count", GpuCurveHeader, node_count);
    EXPECT_FIELD(p, at + "segment_first", GpuCurveHeader, segment_first);
    EXPECT_FIELD(p, at + "flags", GpuCurveHeader, flags);
    EXPECT_FIELD(p, at + "kb", GpuCurveHeader, kb);
    EXPECT_FIELD(p, at + "extra_first", GpuCurveHeader, extra_first);
    EXPECT_FIELD(p, at + "slot", GpuCurveHeader, slot);
    EXPECT_FIELD(p, at + "origin_m[0]", GpuCurveHeader, origin_m);
    EXPECT_FIELD(p, at + "motion[0]", GpuCurveHeader, motion);
}

TEST_F(GpuLayout, RingPassRecordsMatchTheirCppMirrors) {
    auto lod = gfx::make_program({.label = "layout: ring LOD", .compute = ring_lod_program_source()});
    ASSERT_TRUE(lod.ok()) << lod.error().message;
    auto commands = gfx::make_program({.label = "layout: ring commands", .compute = ring_commands_program_source()});
    ASSERT_TRUE(commands.ok()) << commands.error().message;
    auto rings = gfx::make_program({.label = "layout: rings", .compute = ring_build_program_source()});
    ASSERT_TRUE(rings.ok()) << rings.error().message;
    auto place = gfx::make_program({.label = "layout: ring place", .compute = ring_place_program_source()});
    ASSERT_TRUE(place.ok()) << place.error().message;
    // The Job, as the place program reads and writes it (ring ranges, flags, sides).
    EXPECT_EQ(stride(*place, "jobs[0].ring_first"), static_cast<GLint>(sizeof(Job)));
    EXPECT_FIELD(*place, "jobs[0].ring_first", Job, ring_first);
    EXPECT_FIELD(*place, "jobs[0].ring_count", Job, ring_count);
    EXPECT_FIELD(*place, "jobs[0].flags", Job, flags);
    EXPECT_FIELD(*place, "jobs[0].sides", Job, sides);
    // The records both per-wire programs (LOD, rings) declare, on each.
    for (const gfx::Program* program : {&*lod, &*rings}) {
        const gfx::Program& p = *program;
        SCOPED_TRACE(program == &*lod ? "ring LOD program" : "rings program");
        // Job (the ring pass's per-wire record; read back by the nodes path and GpuRingPass).
        EXPECT_EQ(stride(p, "jobs[0].ring_first"), static_cast<GLint>(sizeof(Job)));
        EXPECT_FIELD(p, "jobs[0].ring_first", Job, ring_first);
        EXPECT_FIELD(p, "jobs[0].ring_count", Job, ring_count);
        EXPECT_FIELD(p, "jobs[0].flags", Job, flags);
        EXPECT_FIELD(p, "jobs[0].sides", Job, sides);
        EXPECT_FIELD(p, "jobs[0].previous_normal", Job, previous_normal);
        EXPECT_FIELD(p, "jobs[0].first_normal", Job, first_normal);
        EXPECT_FIELD(p, "jobs[0].totals", Job, totals);
        // SlotState (kept per slot between frames; cleared by the CPU).
        EXPECT_EQ(stride(p, "slot_state[0].lod"), static_cast<GLint>(sizeof(SlotState)));
        EXPECT_FIELD(p, "slot_state[0].lod", SlotState, lod);
        EXPECT_FIELD(p, "slot_state[0].first_normal", SlotState, first_normal);
        // The wire header (GpuCurveHeader), as the ring pass reads it per slot.
        expect_header(p, "headers");
    }
    // The draw record the rings program writes and the vertex shader reads (GpuDraw).
    expect_draw_record(*rings);
    // The indirect commands the commands program writes: 5 words each (DrawElementsIndirectCommand), as a word
    // array.
    EXPECT_EQ(property(*commands, "commands[0]", GL_ARRAY_STRIDE), 4);
}

TEST_F(GpuLayout, CurvePassAndVertexShaderRecordsMatchTheirCppMirrors) {
    auto curves = gfx::make_program({.label = "layout: curves", .compute = curve_program_source()});
    ASSERT_TRUE(curves.ok()) << curves.error().message;
    expect_header(*curves, "headers");       // this upload's, as the CPU wrote them
    expect_header(*curves, "slot_headers");  // the copies it keeps per slot
    EXPECT_EQ(stride(*curves, "refs[0].origin"), static_cast<GLint>(sizeof(MotionRef)));
    EXPECT_FIELD(*curves, "refs[0].origin", MotionRef, origin);
    EXPECT_FIELD(*curves, "refs[0].counts", MotionRef, counts);
    EXPECT_FIELD(*curves, "refs[0].p[0]", MotionRef, p);
    for (const bool draw_parameters : {true, false}) {
        const std::string vertex = vertex_source(false, draw_parameters);
        const std::string fragment = fragment_source(FragmentOutput::color, "", "");
        auto rings = gfx::make_program({.vertex = vertex, .fragment = fragment, .label = "layout: ring vertex"});
        ASSERT_TRUE(rings.ok()) << rings.error().message;
        expect_draw_record(*rings);
        EXPECT_EQ(property(*rings, "chunks[0]", GL_ARRAY_STRIDE), 8);  // kChunkRecordBytes: (draw index, first band)
    }
}

// The helper itself: a name the program does not have reads -1, so a renamed field cannot pass silently.
TEST_F(GpuLayout, AnUnknownFieldReadsAsMissing) {
    auto made = gfx::make_program({.label = "layout: rings", .compute = ring_build_program_source()});
    ASSERT_TRUE(made.ok()) << made.error().message;
    EXPECT_EQ(offset(*made, "jobs[0].no_such_field"), -1);
    EXPECT_GE(offset(*made, "jobs[0].totals"), 0);
}

}  // namespace
