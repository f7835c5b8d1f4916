// The GPU programs' shader storage blocks against the limits of real drivers, read from the assembled GLSL (no GL
// context): llvmpipe allows 32 blocks a stage, NVIDIA 16 and the GL minimum is 8, so a program that grows past
// NVIDIA's limit would link here and fail there. Every block has its own binding, all below 16, and the bindings
// are the ones the C++ names (kBindingMacros: one number for both sides).
#include <gtest/gtest.h>

#include "gpu_wire_data.hpp"
#include "shaders.hpp"

#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace wire::render::detail;

struct Blocks {
    std::vector<int> bindings;  // one per `buffer` block, in source order
    std::vector<std::string> unresolved;
};

/// The binding of every `layout(std430, binding = X) ... buffer` block, X a number or a macro #defined in `source`.
Blocks storage_blocks(const std::string& source) {
    std::map<std::string, int> defines;
    const std::regex define(R"(#define\s+(\w+)\s+(\d+))");
    for (auto it = std::sregex_iterator(source.begin(), source.end(), define); it != std::sregex_iterator(); ++it)
        defines[(*it)[1]] = std::stoi((*it)[2]);
    Blocks out;
    const std::regex block(R"(layout\(std430,\s*binding\s*=\s*(\w+)\)\s*((?:readonly|writeonly|coherent)\s+)?buffer\s)");
    for (auto it = std::sregex_iterator(source.begin(), source.end(), block); it != std::sregex_iterator(); ++it) {
        const std::string b = (*it)[1];
        if (std::isdigit(static_cast<unsigned char>(b[0]))) {
            out.bindings.push_back(std::stoi(b));
        } else if (defines.count(b)) {
            out.bindings.push_back(defines[b]);
        } else {
            out.unresolved.push_back(b);
        }
    }
    return out;
}

TEST(ShaderResources, StorageBlocksFitEveryDesktopDriver) {
    struct Program {
        std::string name, source;
        std::size_t expected_bindings;  // 0: not a table of ours, or the ring pass's (checked together below)
        bool ring_pass;                 // one of the ring pass's programs: their bindings together are RingBinding's
    };
    const std::vector<Program> programs = {
        {"curves", curve_program_source(), kCurveBindings, false},
        {"ring LOD", ring_lod_program_source(), 0, true},
        {"ring place", ring_place_program_source(), 0, true},
        {"ring commands", ring_commands_program_source(), 0, true},
        {"rings", ring_build_program_source(), 0, true},
        {"cpu-mesh vertex", vertex_source(true, true), 0, false},
        {"rings vertex", vertex_source(false, true), 4, false},  // draws, rings, circle, chunks
        {"rings vertex (attribute)", vertex_source(false, false), 4, false},
    };
    std::set<int> ring_pass;
    for (const Program& p : programs) {
        const Blocks b = storage_blocks(p.source);
        EXPECT_TRUE(b.unresolved.empty()) << p.name << ": a binding names no #define: " << b.unresolved.front();
        ASSERT_FALSE(b.bindings.empty()) << p.name << ": no storage block found (the pattern no longer matches)";
        EXPECT_LE(b.bindings.size(), 16u) << p.name << ": more storage blocks than NVIDIA allows a stage";
        const std::set<int> unique(b.bindings.begin(), b.bindings.end());
        EXPECT_EQ(unique.size(), b.bindings.size()) << p.name << ": two blocks share a binding";
        EXPECT_LT(*unique.rbegin(), 16) << p.name << ": a binding at or past 16 fails on drivers with 16 bindings";
        if (p.expected_bindings != 0) {
            // Dense: exactly the enum's bindings 0 .. count - 1, each used.
            EXPECT_EQ(unique.size(), p.expected_bindings) << p.name;
            EXPECT_EQ(*unique.rbegin(), static_cast<int>(p.expected_bindings) - 1) << p.name;
        }
        if (p.ring_pass) ring_pass.insert(unique.begin(), unique.end());
        std::printf("%s: %zu storage blocks, highest binding %d\n", p.name.c_str(), b.bindings.size(), *unique.rbegin());
    }
    // The ring pass's programs between them: dense, exactly the enum's bindings 0 .. count - 1, each used by one
    // of them at least.
    ASSERT_FALSE(ring_pass.empty());
    EXPECT_EQ(ring_pass.size(), static_cast<std::size_t>(kRingBindings));
    EXPECT_EQ(*ring_pass.rbegin(), static_cast<int>(kRingBindings) - 1);
}

// The default uniform block of the compute programs within GL_MAX_COMPUTE_UNIFORM_COMPONENTS' minimum (1024),
// counted as a compiler that gives every scalar, vector and array element its own vec4 slot would (a mat3 three,
// a dvec3 two): a float[257] table came to 1028 on its own.
TEST(ShaderResources, DefaultUniformBlocksFitTheMinimumWithVec4Slots) {
    const std::map<std::string, int> slots = {{"float", 1}, {"int", 1}, {"uint", 1}, {"bool", 1}, {"vec2", 1},
                                              {"vec3", 1}, {"vec4", 1}, {"uvec4", 1}, {"mat3", 3}, {"mat4", 4},
                                              {"dvec3", 2}, {"double", 1}};
    for (const auto& [name, source] : {std::pair{"curves", curve_program_source()},
                                       std::pair{"ring LOD", ring_lod_program_source()},
                                       std::pair{"ring place", ring_place_program_source()},
                                       std::pair{"ring commands", ring_commands_program_source()},
                                       std::pair{"rings", ring_build_program_source()}}) {
        const std::regex uniform(R"((?:^|\n)[ \t]*uniform\s+(\w+)\s+([^;]+);)");  // declarations, not comments
        int components = 0, declared = 0;
        for (auto it = std::sregex_iterator(source.begin(), source.end(), uniform); it != std::sregex_iterator(); ++it) {
            const std::string type = (*it)[1];
            ASSERT_TRUE(slots.count(type)) << name << ": uniform type " << type << " not counted";
            // A comma-separated list of names, each maybe an array.
            const std::string names = (*it)[2];
            const std::regex one(R"((\w+)\s*(\[(\d+)\])?)");
            for (auto n = std::sregex_iterator(names.begin(), names.end(), one); n != std::sregex_iterator(); ++n) {
                const int count = (*n)[3].matched ? std::stoi((*n)[3]) : 1;
                components += 4 * slots.at(type) * count;
                ++declared;
            }
        }
        EXPECT_GT(declared, 0) << name;
        EXPECT_LE(components, 1024) << name << ": default-block uniforms over the minimum with vec4 slots";
        std::printf("%s: %d uniforms, %d components with a vec4 slot each\n", name, declared, components);
    }
}

TEST(ShaderResources, BindingMacrosAreDistinctWithinEachProgram) {
    std::set<std::string> names;
    std::set<uint32_t> curve, ring;
    for (const BindingMacro& m : kBindingMacros) {
        EXPECT_TRUE(names.insert(m.name).second) << m.name;
        const std::string n = m.name;
        auto& set = n.rfind("CURVE_", 0) == 0 ? curve : ring;
        EXPECT_TRUE(set.insert(m.binding).second) << m.name << " repeats binding " << m.binding;
    }
    EXPECT_EQ(curve.size(), static_cast<std::size_t>(kCurveBindings));
    EXPECT_EQ(ring.size(), static_cast<std::size_t>(kRingBindings));
}

}  // namespace

namespace {

// The body of the GLSL function whose definition starts with `signature` in `source` (up to its closing brace at
// the start of a line); empty when it is not found.
std::string function_body(const std::string& source, const std::string& signature) {
    const std::size_t at = source.find(signature);
    if (at == std::string::npos) return {};
    const std::size_t end = source.find("\n}", at);
    return end == std::string::npos ? std::string{} : source.substr(at, end - at);
}

}  // namespace

// node() is inlined at every call site of the curve program (some 60 in the automatic spline's turn weights, in ten
// places): a branch in it multiplied the program's control flow, and llvmpipe took 7 minutes to compile the program
// cold (a fresh machine's first nodes-path frame); branch-free, 9 s. Its two formats are decoded and one selected.
TEST(ShaderResources, CurveProgramHasNoBranchInNode) {
    const std::string body = function_body(curve_program_source(), "vec3 node(GpuCurveHeader h, uint j) {");
    ASSERT_FALSE(body.empty()) << "node() not found in the curve program";
    EXPECT_EQ(body.find("if ("), std::string::npos) << body;
    EXPECT_EQ(body.find("for ("), std::string::npos) << body;
    std::size_t returns = 0;
    for (std::size_t p = body.find("return"); p != std::string::npos; p = body.find("return", p + 1)) ++returns;
    EXPECT_EQ(returns, 1u) << body;
}
