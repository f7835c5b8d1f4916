// The front end of WireRenderer::draw() (renderer_state.hpp): the items with geometry sorted into runs of
// (class, material), the program of the output, the frame's GL state, the stream region, and one submission
// loop issuing a glMultiDrawElementsIndirect per run; the path's back end prepares and binds the frame in
// between. The nodes path's frame (draw_nodes) runs its compute stages and submits through NodePath.
#include "renderer_state.hpp"

#include <epoxy/gl.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <string>

namespace wire::render {

namespace gfx = engine::gfx;
using gfx::StreamRegion;

DrawStats& WireRenderer::State::failed(DrawStats& stats, const Status& why) {
    stats.status = why;
    if (std::find(logged.begin(), logged.end(), why.message) == logged.end()) {
        logged.push_back(why.message);
        std::fprintf(stderr, "wire renderer: %s\n", why.message.c_str());
    }
    return stats;
}

const detail::gfx::Program* WireRenderer::State::program_for(bool cpu, Output output, Status& why) {
    if (output == Output::color) return cpu ? &cpu_program : &rings_program;
    const bool depth = output == Output::depth || output == Output::shadow;
    gfx::Program& program = (depth ? depth_programs : gbuffer_programs)[cpu ? 0 : 1];
    if (program.id() != 0) return &program;
    const std::string fragment = detail::fragment_source(
        depth ? detail::FragmentOutput::depth : detail::FragmentOutput::gbuffer, {}, gbuffer_glsl);
    const std::string label =
        std::string(cpu ? "wire cpu-mesh" : "wire rings") + (depth ? " depth" : " gbuffer");
    Expected<gfx::Program> made =
        gfx::make_program({.vertex = cpu ? cpu_vertex : rings_vertex, .fragment = fragment, .label = label});
    if (!made) {
        why = Status::error(label + ": " + made.error().message);
        return nullptr;
    }
    program = std::move(made).value();
    return &program;
}

WireRenderer::State::View WireRenderer::State::view_of(const engine::scene::Camera& camera) {
    GLint viewport[4] = {0, 0, 1, 1};
    glGetIntegerv(GL_VIEWPORT, viewport);
    const double w = std::max(viewport[2], 1), h = std::max(viewport[3], 1);
    View v{camera, {}};
    const engine::scene::Camera& c = v.camera;
    if (!c.orthographic()) {
        v.lod = LodView::perspective(c.position, c.target, c.up, c.fov_y_rad, w, h, c.near_m, c.far_m);
        return v;
    }
    v.lod = LodView::orthographic(c.position, c.target, c.up, c.ortho_half_height_m, w, h, c.near_m, c.far_m);
    const double back = LodView::orthographic_back_m(c.ortho_half_height_m, c.near_m, c.far_m);
    v.camera.target += v.lod.eye_m - v.camera.position;
    v.camera.position = v.lod.eye_m;
    v.camera.near_m = static_cast<float>(back + c.near_m);
    v.camera.far_m = static_cast<float>(back + c.far_m);
    return v;
}

void WireRenderer::State::begin_wires(const detail::gfx::Program& program,
                                      const engine::scene::Camera& camera, const DrawSettings& settings) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);  // front faces only: culling stays on
    program.use();
    // Camera-relative: the view is the camera's rotation only; positions arrive as offsets from the eye.
    program.set("u_clip_from_rel", camera.clip_from_relative());
    program.set("u_to_light", glm::normalize(settings.light.to_light));
    program.set("u_light_color", settings.light.color);
    program.set("u_ambient", settings.light.ambient);
    program.set("u_specular", settings.light.specular);
    program.set("u_shininess", settings.light.shininess);
    GLint viewport[4] = {0, 0, 1, 1};
    glGetIntegerv(GL_VIEWPORT, viewport);
    program.set("u_viewport_px", glm::vec2(static_cast<float>(std::max(viewport[2], 1)),
                                           static_cast<float>(std::max(viewport[3], 1))));
    program.set("u_focal_px", camera.focal_px(static_cast<float>(std::max(viewport[3], 1))));
    program.set("u_push_back", settings.output == Output::shadow ? 1 : 0);
    if (settings.output == Output::shadow) glCullFace(GL_FRONT);  // the far side (end_wires() restores)
    if (settings.output == Output::color) gfx::set_shadow_uniforms(program, settings.shadow, camera.position);
}

DrawStats WireRenderer::State::draw_nodes(const DrawList& list, const engine::scene::Camera& camera,
                                          const DrawSettings& settings) {
    DrawStats stats;
    if (Status st = ensure_nodes(); !st) return failed(stats, st);
    nodes->set_lod(list.lod);  // the systems' LOD, evaluated on the GPU
    if (Status st = ensure_patterns(nodes->max_sides()); !st) return failed(stats, st);
    const std::size_t bytes = nodes->upload_bytes(list);
    Expected<StreamRegion> begun = stream.begin(bytes);
    if (!begun) return failed(stats, begun.error());
    stats.buffer_grew = begun->grew;
    stats.waited_for_gpu = begun->waited;
    Status no_program;
    const gfx::Program* program = program_for(false, settings.output, no_program);
    if (program == nullptr) {
        stream.end();
        return failed(stats, no_program);
    }
    const detail::NodeDrawContext ctx{*program,  rings_vao, circle.id(),    pattern_first,
                                      materials, textures,  draw_parameters};
    const View view = view_of(camera);
    const bool drawn =
        nodes->prepare(list, view.lod, std::min(settings.view, kMaxViews - 1), *begun, ctx, stats);
    const bool streamed = node_stream && detail::stream_active(*node_stream);
    if (!stats.status.ok()) failed(stats, stats.status);
    Status index_capacity = drawn ? ensure_draw_index_capacity(nodes->chunk_capacity()) : Status::success();
    if (!index_capacity) failed(stats, index_capacity);
    if (drawn && index_capacity) {
        begin_wires(*program, view.camera, settings);
        using Lines = detail::NodePath::Lines;
        nodes->submit(ctx, stats,
                      settings.output == Output::color   ? Lines::blended
                      : settings.output == Output::depth ? Lines::skipped
                                                         : Lines::opaque);
        glBindVertexArray(0);
        glCullFace(GL_BACK);
        if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
    stream.end();
    if (streamed) detail::end_stream_frame(*node_stream);  // after the dispatches that read its region
    return stats;
}

DrawStats WireRenderer::draw(const DrawList& list, const engine::scene::Camera& camera,
                             const DrawSettings& settings) {
    State& s = *state_;
    s.last_path = list.path;
    s.drawn_any = true;
    s.long_drawn.clear();
    if (list.path == UploadPath::gpu_nodes) {
        const bool any_long = std::any_of(list.items.begin(), list.items.end(), [](const DrawItem& item) {
            return detail::node_count(item) > kNodesPathMaxNodes;
        });
        return any_long ? s.draw_with_long_wires(list, camera, settings) : s.draw_nodes(list, camera, settings);
    }
    DrawStats stats;
    if (s.node_stream && detail::stream_active(*s.node_stream)) {
        // The stream's wires are computed by the nodes path only: said, not dropped in silence; the list
        // draws.
        detail::end_stream_frame(*s.node_stream);
        s.failed(stats,
                 Status::error("the node stream's wires draw on the nodes path; this draw list is on '" +
                               std::string(upload_path_name(list.path)) + "': they were not drawn"));
    }
    return s.draw_mesh(list, camera, settings, stats);
}

DrawStats WireRenderer::State::draw_mesh(const DrawList& list, const engine::scene::Camera& camera,
                                         const DrawSettings& settings, DrawStats stats) {
    State& s = *this;
    // cpu-mesh. (1) Items with geometry: opaque items (tubes, strips) first, then the blended phone-wire lines
    // (sides 1), each by material (stable: equal materials keep the list's order).
    s.order.clear();
    for (uint32_t i = 0; i < list.items.size(); ++i) {
        const DrawItem& item = list.items[i];
        assert(item.material < s.materials.size() && "DrawItem::material out of range");
        if (!has_geometry(item)) continue;
        s.order.push_back(i);
    }
    std::stable_sort(s.order.begin(), s.order.end(), [&](uint32_t a, uint32_t b) {
        const DrawItem& x = list.items[a];
        const DrawItem& y = list.items[b];
        if (detail::blended(x) != detail::blended(y)) return detail::blended(y);
        return x.material < y.material;
    });
    if (s.order.empty()) return stats;  // nothing to draw: no draw call

    // (2) The back end: runs, commands and the region's contents.
    const State::View view = State::view_of(camera);
    detail::ListFrame frame;
    if (const Status prepared = s.prepare_mesh(list, view.camera.position, frame, stats); !prepared)
        return s.failed(stats, prepared);  // no region: the frame's wires are skipped, the rest goes on

    // (3) Submit: GL state for the wires, the mode's program, the back end's bindings, one multi-draw per
    // run.
    Status no_program;
    const gfx::Program* chosen = s.program_for(true, settings.output, no_program);
    if (chosen == nullptr) {
        s.stream.end();
        return s.failed(stats, no_program);
    }
    const gfx::Program& program = *chosen;
    s.begin_wires(program, view.camera, settings);
    const StreamRegion& region = frame.region;
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, region.buffer, static_cast<GLintptr>(region.offset_bytes),
                      static_cast<GLsizeiptr>(frame.draws_bytes));
    s.bind_mesh(frame);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, region.buffer);
    bool blending = false;
    for (std::size_t run = 0; run + 1 < s.run_first.size(); ++run) {
        const DrawItem& head = list.items[s.order[s.run_first[run]]];
        const bool line = detail::blended(head);
        if (line && settings.output == Output::depth)
            break;  // translucent: no depth in a pre-pass (lines run last)
        // Phone-wire lines: opacity = true width / drawn width, over the opaque wires (colour output only).
        if (line && !blending && settings.output == Output::color) {
            glEnable(GL_BLEND);
            glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            glDepthMask(GL_FALSE);
            blending = true;
        }
        const Material& material = s.materials[head.material];
        program.set("u_tint", material.tint);
        program.set("u_roughness", material.roughness);
        s.textures[material.texture].bind(0);
        const auto* indirect =
            reinterpret_cast<const void*>(region.offset_bytes + frame.command_offset +
                                          s.run_command[run] * sizeof(detail::DrawElementsIndirectCommand));
        const auto count = static_cast<GLsizei>(s.run_command[run + 1] - s.run_command[run]);
        glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, indirect, count, 0);
        ++stats.multi_draw_calls;
    }
    if (blending) {
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
    }
    s.stream.end();

    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glBindVertexArray(0);
    glCullFace(GL_BACK);
    if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    return stats;
}

}  // namespace wire::render
