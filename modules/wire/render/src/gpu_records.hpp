// Internal: the records and flag bits shared with the GLSL (shaders/gpu_records.h, one text valid in both),
// read as C++: GLSL's scalar and vector types with std430's sizes and alignments, then the shared text.
#pragma once

#include <cstddef>
#include <cstdint>

#include "wire/packed_nodes.hpp"

namespace wire::render::detail {

using uint = std::uint32_t;
/// 12 bytes; std430 aligns a vec3 to 16, so the shared records place one only at an offset of 16.
struct vec3 {
    float x = 0.0f, y = 0.0f, z = 0.0f;
};
struct alignas(16) vec4 {
    float x = 0.0f, y = 0.0f, z = 0.0f, w = 0.0f;
};
struct alignas(16) uvec4 {
    uint x = 0, y = 0, z = 0, w = 0;
};

#define WIRE_CONST inline constexpr
#define WIRE_ZERO {}
#include "../shaders/gpu_records.h"
#undef WIRE_CONST
#undef WIRE_ZERO

static_assert(sizeof(GpuCurveHeader) == 64, "the 64-byte std430 wire header");
static_assert(sizeof(MotionRef) == 192, "the curve pass's std430 motion reference");
static_assert(sizeof(Job) == 64, "the ring pass's std430 job record");
static_assert(sizeof(SlotState) == 32, "the ring pass's std430 slot record");
static_assert(sizeof(GpuDraw) == 32, "the std430 draw record");
static_assert(kQuantBits == wire::kQuantBits && kQuantMask == wire::kQuantMask && kQuantBias == wire::kQuantBias &&
                  kQuantExpBias == wire::kQuantExpBias,
              "pack_nodes' quantised format is the one the curve program decodes");

}  // namespace wire::render::detail
