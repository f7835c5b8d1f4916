// Consumer of the installed wires package: runs README.md's "Wires from game code" example unchanged in a
// headless GL context, then checks that the wire was drawn where its nodes project. Exit 0 on success, 1 with
// a message on failure.
#include <wire/render/install.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <curved_space/segments_json.hpp>
#include <engine/assets/gltf.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/io/wire_json.hpp>

#include <glm/glm.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

int fail(const std::string& message) {
    std::fprintf(stderr, "wires_consumer: %s\n", message.c_str());
    return 1;
}

// A cable across the default camera's view (engine::scene::Camera looks from z = 5 at the origin).
wire::WireNodes hanging_cable(int n, double sag_m) {
    wire::WireNodes nodes;
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        nodes.positions.emplace_back(-1.5 + 3.0 * s, 0.3 - 4.0 * sag_m * s * (1.0 - s), 0.0);
    }
    return nodes;
}

// README.md "Wires from game code", verbatim (see CMakeLists.txt). Its names: nodes, moved_nodes, midpoint,
// renderer; it declares registry, schedule, context and w itself, sets the camera (from z = 5 at the origin)
// and the 960x540 viewport, and adds material 1.
template <class Renderer>
engine::scene::Camera readme_example(const wire::WireNodes& nodes, const wire::WireNodes& moved_nodes,
                                     const glm::dvec3& midpoint, Renderer& renderer) {
#include "readme_example.inc"
    return context.camera;
}

bool background(const std::uint8_t* p, const glm::vec4& clear) {
    for (int c = 0; c < 3; ++c) {
        if (std::abs(p[c] - clear[c] * 255.0f) > 12.0f) return false;
    }
    return true;
}

}  // namespace

int main() {
    // Every library's link interface: these pull in tinygltf + stb, OpenSubdiv and nlohmann_json code.
    std::vector<engine::assets::MeshData> meshes;
    if (engine::assets::read_gltf("/nonexistent/wires_consumer.glb", meshes).ok()) {
        return fail("read_gltf accepted a missing file");
    }
    engine::assets::MeshData coarse;
    engine::assets::MeshData fine;
    if (engine::assets::subdivide(coarse, 1, fine).ok()) return fail("subdivide accepted an empty mesh");
    std::vector<curved_space::Segment> segments;
    if (!curved_space::parse_segments_json(R"({"segments": [{"length": 2.0, "angle": 0.5}]})", "segs",
                                           segments) ||
        segments.size() != 1) {
        return fail("parse_segments_json failed");
    }
    wire::io::SceneSpec spec;
    if (!wire::io::parse_wire_json(R"({"nodes": [[0,0,0],[1,0,0]]})", "wire", spec)) {
        return fail("parse_wire_json failed");
    }

    const int width = 960;
    const int height = 540;
    auto context_or = engine::platform::create_headless_context({.width = width, .height = height});
    if (!context_or) return fail("headless GL context: " + context_or.error().message);
    engine::platform::Context& gl = **context_or;
    auto renderer = wire::render::WireRenderer::create();
    if (!renderer) return fail("WireRenderer::create: " + renderer.error().message);
    // The README's example adds material 1 itself (a light blue; material 0 is the built-in copper weave).

    const wire::WireNodes nodes = hanging_cable(16, 0.2);
    const wire::WireNodes moved_nodes = hanging_cable(16, 0.3);
    const glm::dvec3 midpoint = 0.5 * (moved_nodes.positions[7] + moved_nodes.positions[8]);
    const glm::vec4 clear{0.1f, 0.1f, 0.12f, 1.0f};
    gl.begin_frame();
    engine::gfx::clear(clear);
    const engine::scene::Camera camera = readme_example(nodes, moved_nodes, midpoint, renderer);
    const engine::platform::Image image = engine::platform::read_pixels(gl);
    gl.end_frame();

    // Drawn where the nodes project, in material 1: a blue pixel within 2 px of every moved node.
    const glm::mat4 clip_from_world = camera.view_projection();
    int hits = 0;
    for (const glm::dvec3& p : moved_nodes.positions) {
        const glm::vec4 clip = clip_from_world * glm::vec4(glm::vec3(p), 1.0f);
        const int x = static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * width);
        const int y = static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * height);
        bool hit = false;
        for (int dy = -2; dy <= 2 && !hit; ++dy) {
            for (int dx = -2; dx <= 2 && !hit; ++dx) {
                const int px = x + dx;
                const int py = y + dy;
                if (px < 0 || py < 0 || px >= width || py >= height) continue;
                const std::uint8_t* c = image.pixel(px, py);
                hit = !background(c, clear) && c[2] > c[0] + 20;  // material 1's blue
            }
        }
        hits += hit ? 1 : 0;
    }
    // And nowhere else: the wire spans x in [-1.5, 1.5], y in [-0.3, 0.3]; the top and bottom fifth stay
    // empty.
    long stray = 0;
    long drawn = 0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            if (background(image.pixel(x, y), clear)) continue;
            ++drawn;
            if (y < height / 5 || y >= height - height / 5) ++stray;
        }
    }
    std::printf("wires_consumer: %s; %d/%zu nodes drawn, %ld wire pixels, %ld stray\n",
                gl.gl_renderer().c_str(), hits, moved_nodes.positions.size(), drawn, stray);
    if (hits != static_cast<int>(moved_nodes.positions.size()))
        return fail("the wire is not drawn at its nodes");
    if (stray != 0) return fail("pixels drawn away from the wire");
    if (const char* out = std::getenv("WIRES_CONSUMER_PNG")) {
        if (!engine::platform::write_png(out, image)) return fail(std::string("could not write ") + out);
    }
    return 0;
}
