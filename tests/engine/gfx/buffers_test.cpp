// engine/gfx upload helpers: RangeAllocator (CPU, random operations against a byte map), RetainedBuffer and
// StreamBuffer (headless llvmpipe: data survives growth, freed ranges wait for their fence, retired buffers are
// deleted), GpuTimer (results arrive later without stalling, and are plausible).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "engine/gfx/debug.hpp"
#include "engine/gfx/gpu_timer.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/gfx/range_allocator.hpp"
#include "engine/gfx/retained_buffer.hpp"
#include "engine/gfx/stream_buffer.hpp"
#include "engine/platform/context.hpp"

namespace {

namespace gfx = engine::gfx;
namespace platform = engine::platform;

// Random allocate/free/grow sequences (fixed seeds) checked against a map of who owns each byte: ranges never
// overlap, stay inside the capacity, are aligned; free space is coalesced (no two free ranges touch) and the
// used count is exact; after freeing everything one free range spans the whole capacity.
TEST(RangeAllocatorTest, RandomOperationsMatchByteMap) {
    for (uint32_t seed = 1; seed <= 20; ++seed) {
        std::mt19937 rng(seed);
        const std::size_t alignment = std::size_t{1} << (seed % 6);  // 1 .. 32
        gfx::RangeAllocator a(4096, alignment);
        std::vector<int> owner(a.capacity(), -1);
        struct Live {
            std::size_t offset, bytes;
            int id;
        };
        std::vector<Live> live;
        int next_id = 0;
        std::size_t failures = 0;
        for (int op = 0; op < 2000; ++op) {
            const uint32_t kind = rng() % 100;
            if (kind < 52) {
                const std::size_t bytes = 1 + rng() % 300;
                const std::optional<std::size_t> at = a.allocate(bytes);
                if (!at) {
                    ++failures;
                    // It must really not fit: no run of free bytes that long at an aligned offset.
                    EXPECT_LT(a.largest_free(), a.rounded(bytes)) << "seed " << seed;
                    continue;
                }
                ASSERT_EQ(*at % alignment, 0u);
                ASSERT_LE(*at + a.rounded(bytes), a.capacity());
                for (std::size_t b = *at; b < *at + a.rounded(bytes); ++b) {
                    ASSERT_EQ(owner[b], -1) << "seed " << seed << " op " << op << ": overlap at byte " << b;
                    owner[b] = next_id;
                }
                live.push_back({*at, bytes, next_id++});
            } else if (kind < 97 && !live.empty()) {
                const std::size_t i = rng() % live.size();
                a.free(live[i].offset, live[i].bytes);
                for (std::size_t b = live[i].offset; b < live[i].offset + a.rounded(live[i].bytes); ++b)
                    owner[b] = -1;
                live.erase(live.begin() + static_cast<long>(i));
            } else if (kind >= 97 && a.capacity() < 8192) {
                a.grow(a.capacity() + 1000);
                owner.resize(a.capacity(), -1);
            }
            // Invariants.
            std::size_t used = 0;
            for (int o : owner) used += o >= 0 ? 1 : 0;
            ASSERT_EQ(a.used_bytes(), used) << "seed " << seed << " op " << op;
            std::size_t prev_end = SIZE_MAX;
            for (const auto& [offset, size] : a.free_list()) {
                ASSERT_NE(offset, prev_end) << "adjacent free ranges not merged";
                for (std::size_t b = offset; b < offset + size; ++b) ASSERT_EQ(owner[b], -1);
                prev_end = offset + size;
            }
        }
        for (const Live& l : live) a.free(l.offset, l.bytes);
        EXPECT_EQ(a.used_bytes(), 0u);
        ASSERT_EQ(a.free_ranges(), 1u);
        EXPECT_EQ(a.free_list().begin()->second, a.capacity());
        EXPECT_GT(failures, 0u) << "the sequence should have filled the allocator at least once";
    }
}

TEST(RangeAllocatorTest, BestFitIsDeterministic) {
    gfx::RangeAllocator a(1000, 1);
    const auto x = a.allocate(100), y = a.allocate(50), z = a.allocate(200), w = a.allocate(60);
    ASSERT_TRUE(x && y && z && w);
    a.free(*y, 50);  // hole of 50 at 100
    a.free(*w, 60);  // merges with the tail: free [350, 1000)
    EXPECT_EQ(a.allocate(40), std::optional<std::size_t>(100));  // the smallest hole that fits
    EXPECT_EQ(a.allocate(20), std::optional<std::size_t>(350));  // 10 left at 140 is too small
    EXPECT_EQ(a.allocate(10), std::optional<std::size_t>(140));
    EXPECT_FALSE(a.allocate(1000).has_value());
}

class GlBuffersTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto ctx = platform::create_headless_context({.width = 32, .height = 32, .quiet = true});
        ASSERT_TRUE(ctx.ok()) << ctx.error().message;  // fails, not skips, without a context
        context_ = std::move(ctx).value();
    }
    std::unique_ptr<platform::Context> context_;
};

std::vector<uint32_t> read_back(unsigned buffer, std::size_t offset, std::size_t words) {
    std::vector<uint32_t> out(words);
    glGetNamedBufferSubData(buffer, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(words * 4), out.data());
    return out;
}

// Ranges keep their contents across growth (copied on the GPU at the same offsets); a freed range is not
// handed out again before its frame's fence has signalled; retired buffers are deleted once their fences pass.
TEST_F(GlBuffersTest, RetainedBufferKeepsDataAcrossGrowthAndFencesReuse) {
    auto made = gfx::RetainedBuffer::create({.initial_bytes = 256, .alignment = 16, .label = "test retained"});
    ASSERT_TRUE(made.ok()) << made.error().message;
    gfx::RetainedBuffer buf = std::move(made).value();
    std::mt19937 rng(7);
    struct Live {
        gfx::RetainedRange range;
        uint32_t tag;
    };
    std::vector<Live> live;
    uint32_t tag = 1;
    std::size_t growths = 0;
    for (int frame = 0; frame < 60; ++frame) {
        buf.begin_frame();
        for (int k = 0; k < 4; ++k) {
            const std::size_t words = 1 + rng() % 40;
            auto r = buf.allocate(words * 4);
            ASSERT_TRUE(r.ok()) << r.error().message;
            growths += r->grew ? 1 : 0;
            std::vector<uint32_t> data(words, tag);
            std::memcpy(r->data, data.data(), words * 4);
            live.push_back({*r, tag++});
        }
        // Free a few: none of them may be reused this frame (their fences are not placed yet).
        std::vector<gfx::RetainedRange> freed;
        for (int k = 0; k < 2 && !live.empty(); ++k) {
            const std::size_t i = rng() % live.size();
            buf.free(live[i].range);
            freed.push_back(live[i].range);
            live.erase(live.begin() + static_cast<long>(i));
        }
        auto r = buf.allocate(16);
        ASSERT_TRUE(r.ok());
        for (const gfx::RetainedRange& f : freed)
            EXPECT_FALSE(r->offset_bytes < f.offset_bytes + f.size_bytes && f.offset_bytes < r->offset_bytes + 16)
                << "a range freed this frame was handed out again before its fence";
        buf.free(*r);
        buf.end_frame();
        glFinish();
        // Every live range still holds its tag in the current buffer.
        for (const Live& l : live) {
            const std::vector<uint32_t> got = read_back(buf.buffer(), l.range.offset_bytes, l.range.size_bytes / 4);
            ASSERT_TRUE(std::all_of(got.begin(), got.end(), [&](uint32_t v) { return v == l.tag; }))
                << "frame " << frame << ": range at " << l.range.offset_bytes << " lost its data";
        }
    }
    EXPECT_GE(growths, 2u);
    glFinish();
    buf.begin_frame();
    EXPECT_EQ(buf.live_buffers(), 1u);
    EXPECT_EQ(buf.pending_bytes(), 0u);
    const std::vector<unsigned>& all = buf.allocated_buffers();
    EXPECT_EQ(all.size(), growths + 1);
    // A retired buffer's name is gone, or the driver recycled it: for a later buffer of this object (the current
    // one; an older one would have been retired and deleted too) or for another object (another label).
    ASSERT_EQ(all.back(), buf.buffer());
    for (std::size_t i = 0; i + 1 < all.size(); ++i)
        EXPECT_TRUE(!glIsBuffer(all[i]) || all[i] == buf.buffer() || gfx::buffer_label(all[i]) != "test retained")
            << "retired buffer " << all[i] << " kept";
    std::size_t live_bytes = 0;
    for (const Live& l : live) live_bytes += buf.allocator().rounded(l.range.size_bytes);
    EXPECT_EQ(buf.live_bytes(), live_bytes);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(GlBuffersTest, StreamBufferRegionsRotateAndGrow) {
    auto made = gfx::StreamBuffer::create({.regions = 3, .region_bytes = 256, .label = "test stream"});
    ASSERT_TRUE(made.ok()) << made.error().message;
    gfx::StreamBuffer sb = std::move(made).value();
    std::vector<std::size_t> offsets;
    for (int i = 0; i < 4; ++i) {
        auto r = sb.begin(100);
        ASSERT_TRUE(r.ok());
        offsets.push_back(r->offset_bytes);
        sb.end();
    }
    EXPECT_EQ(offsets[0], 0u);
    EXPECT_EQ(offsets[1], 256u);
    EXPECT_EQ(offsets[2], 512u);
    EXPECT_EQ(offsets[3], 0u);
    auto big = sb.begin(1000);
    ASSERT_TRUE(big.ok());
    EXPECT_TRUE(big->grew);
    EXPECT_GE(big->size_bytes, 1000u);
    sb.end();
    glFinish();
    auto next = sb.begin(10);
    ASSERT_TRUE(next.ok());
    sb.end();
    EXPECT_EQ(sb.live_buffers(), 1u);
    const unsigned retired = sb.allocated_buffers().front();  // gone, or recycled as the current buffer
    EXPECT_TRUE(!glIsBuffer(retired) || retired == sb.allocated_buffers().back() ||
                gfx::buffer_label(retired) != "test stream");
}

// A full-screen triangle whose every fragment runs a dependent chain of `iterations` steps: GPU work that grows
// with the count on any driver (clears do not: hardware clears are nearly free whatever their number).
constexpr const char* kBusyVertex = R"(#version 450 core
void main() { gl_Position = vec4(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0, 0.0, 1.0); })";
constexpr const char* kBusyFragment = R"(#version 450 core
uniform int iterations;
out vec4 color;
void main() {
    float x = gl_FragCoord.x * 0.013 + gl_FragCoord.y * 0.007;
    for (int i = 0; i < iterations; ++i) x = fract(sin(x * 12.9898 + float(i)) * 43758.5453);
    color = vec4(x, 0.5, 0.5, 1.0);
})";

// Timer results come back through poll() once the GPU is done, in order, never blocking: with the GPU kept
// idle between frames (glFinish) every frame's result is available at the next poll and none is skipped; a pass
// doing more work takes longer; without waiting, frames whose queries are all pending are skipped, not waited
// for, and every begin() is accounted for.
TEST_F(GlBuffersTest, GpuTimerMeasuresWithoutStalling) {
    auto busy_program = gfx::make_program({.vertex = kBusyVertex, .fragment = kBusyFragment, .label = "busy"});
    ASSERT_TRUE(busy_program.ok()) << busy_program.error().message;
    unsigned vao = 0;
    glCreateVertexArrays(1, &vao);
    glBindVertexArray(vao);
    busy_program->use();
    gfx::GpuTimer timer = gfx::GpuTimer::create(4);
    std::vector<gfx::GpuTimer::Measurement> got;
    for (int frame = 0; frame < 12; ++frame) {
        timer.begin();
        busy_program->set("iterations", 200 * (1 + 4 * frame));  // 45x the work in the last frame
        glDrawArrays(GL_TRIANGLES, 0, 3);
        timer.end();
        gfx::finish_gpu();
        for (const auto& m : timer.poll()) got.push_back(m);
    }
    EXPECT_EQ(timer.skipped(), 0u);
    EXPECT_EQ(got.size() + timer.rejected(), 12u);
    EXPECT_LE(timer.rejected(), 1u) << "only a query begun before any scene (llvmpipe) is impossible";
    std::printf("%zu measured, %llu rejected:", got.size(), static_cast<unsigned long long>(timer.rejected()));
    for (std::size_t i = 0; i < got.size(); ++i) {
        std::printf(" %.4f", got[i].ms);
        EXPECT_GE(got[i].ms, 0.0);
        if (i > 0) {
            EXPECT_GT(got[i].frame, got[i - 1].frame) << "results in order";
        }
    }
    std::printf(" ms\n");
    ASSERT_GE(got.size(), 2u);
    EXPECT_GT(got.back().ms, got.front().ms) << "45x the fragment work takes longer";
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &vao);
    ASSERT_TRUE(timer.latest().has_value());
    EXPECT_EQ(timer.latest()->frame, got.back().frame);

    gfx::GpuTimer busy = gfx::GpuTimer::create(2);
    std::size_t measured = 0;
    for (int frame = 0; frame < 50; ++frame) {
        busy.begin();
        glClear(GL_COLOR_BUFFER_BIT);
        busy.end();
        measured += busy.poll().size();
    }
    measured += busy.finish().size();
    EXPECT_EQ(measured + busy.skipped() + busy.rejected(), 50u);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
