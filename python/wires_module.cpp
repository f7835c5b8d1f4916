// The Python module `wires` (pybind11): a wire runtime a simulation script drives with numpy arrays.
// Everything runs through the C++ runtime itself (wire entities in the ECS registry, the installed wire
// systems, the wire renderer in a GL context, wire::systems::wire_ring_set for read-back); this file only
// converts arrays and errors.
#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/pipeline.hpp>
#include <wire/render/node_stream.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/global_control.h>
#include <glm/glm.hpp>

#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;

namespace {

using engine::ecs::Entity;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using IdArray = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;

/// Raised for wires whose nodes the runtime rejects (a ValueError carrying the runtime's message).
PyObject* g_wire_error = nullptr;

[[noreturn]] void value_error(const std::string& message) {
    throw py::value_error(message);
}

// ---- numpy -> WireNodes ----

/// (N, 3) float64 positions (anything numpy converts), N >= 0; `what` names the argument in messages.
void check_positions(const DoubleArray& a, const std::string& what) {
    if (a.ndim() != 2 || a.shape(1) != 3)
        value_error(what + ": expected an array of shape (N, 3), got " + std::to_string(a.ndim()) +
                    " dimensions" +
                    (a.ndim() == 2 ? " (N, " + std::to_string(a.shape(1)) + ")" : std::string()));
}

void read_positions(const DoubleArray& a, const std::string& what, std::vector<glm::dvec3>& out) {
    check_positions(a, what);
    const auto n = static_cast<std::size_t>(a.shape(0));
    const double* p = a.data();
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
}

template <class T, class Array>
void read_per_node(const std::optional<Array>& a, std::size_t n, const std::string& what,
                   std::vector<T>& out) {
    out.clear();
    if (!a) return;
    if (a->ndim() != 1 || static_cast<std::size_t>(a->shape(0)) != n)
        value_error(what + ": expected one value per node (shape (" + std::to_string(n) + ",)), got shape " +
                    (a->ndim() == 1 ? "(" + std::to_string(a->shape(0)) + ",)"
                                    : std::to_string(a->ndim()) + "-dimensional"));
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i) out.push_back(static_cast<T>(a->data()[i]));
}

wire::WireNodes to_nodes(const DoubleArray& positions, const std::optional<IdArray>& ids,
                         const std::optional<FloatArray>& stretch, const std::optional<FloatArray>& radii) {
    wire::WireNodes n;
    read_positions(positions, "positions", n.positions);
    if (ids) {
        std::vector<int64_t> raw;
        read_per_node(ids, n.size(), "ids", raw);
        n.ids.reserve(raw.size());
        for (std::size_t i = 0; i < raw.size(); ++i) {
            if (raw[i] < 0 || raw[i] > 0xFFFFFFFFll)
                value_error("ids: node " + std::to_string(i) + ": id " + std::to_string(raw[i]) +
                            " is outside [0, 2^32)");
            n.ids.push_back(static_cast<uint32_t>(raw[i]));
        }
    }
    read_per_node(stretch, n.size(), "stretch", n.stretch);
    read_per_node(radii, n.size(), "radii", n.radius_m);
    return n;
}

wire::SplineSettings spline_of(const std::string& name) {
    // The names wiretool and the wire JSON use (wire_io's resolve_settings).
    wire::io::WireSpec spec;
    spec.spline_type = name;
    wire::PipelineSettings s;
    if (engine::Status st = wire::io::resolve_settings(spec, {}, s); !st.ok())
        value_error("spline: " + st.message);
    return s.spline;
}

wire::UploadPath path_of(const std::string& name) {
    if (const std::string_view note = wire::retired_path_note(name); !note.empty())
        if (PyErr_WarnEx(PyExc_DeprecationWarning, std::string(note).c_str(), 2) < 0) throw py::error_already_set();
    if (const std::optional<wire::UploadPath> p = wire::parse_upload_path(name)) return *p;
    value_error("path: expected 'auto', 'nodes' or 'cpu', got '" + name + "'");
}

glm::dvec3 vec3_of(const std::vector<double>& v, const char* what) {
    if (v.size() != 3 || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
        value_error(std::string(what) + ": expected 3 finite numbers");
    return {v[0], v[1], v[2]};
}

// ---- ring read-back ----

py::dict rings_dict(const wire::RingSet& r) {
    const auto n = static_cast<py::ssize_t>(r.params.size());
    py::array_t<double> centres({n, py::ssize_t{3}}), tangents({n, py::ssize_t{3}}),
        normals({n, py::ssize_t{3}}), binormals({n, py::ssize_t{3}});
    py::array_t<double> radius(n), u(n), t(n);
    py::array_t<uint32_t> segment(n);
    double *c = centres.mutable_data(), *ta = tangents.mutable_data(), *no = normals.mutable_data(),
           *bi = binormals.mutable_data();
    for (py::ssize_t i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const glm::dvec3 p = r.origin_m + r.centre_m[k];
        const wire::Frame& f = r.frames[k];
        for (int j = 0; j < 3; ++j) {
            c[3 * i + j] = p[j];
            ta[3 * i + j] = f.t[j];
            no[3 * i + j] = f.r[j];
            bi[3 * i + j] = f.s[j];
        }
        radius.mutable_data()[i] = static_cast<double>(r.rings[k].radius_m);
        u.mutable_data()[i] = r.u[k];
        t.mutable_data()[i] = r.params[k].t;
        segment.mutable_data()[i] = r.params[k].segment;
    }
    py::dict d;
    d["centres"] = centres;
    d["tangents"] = tangents;
    d["normals"] = normals;
    d["binormals"] = binormals;
    d["radius"] = radius;
    d["u"] = u;
    d["segment"] = segment;
    d["t"] = t;
    return d;
}

// ---- the runtime ----

/// One scene: a GL context, the wire renderer, a registry with the installed wire systems.
class Runtime {
public:
    Runtime(int width, int height, bool headless, const std::string& path, int threads, bool pop_free) {
        if (width < 1 || height < 1 || width > 16384 || height > 16384)
            value_error("size: expected width and height in [1, 16384], got " + std::to_string(width) + "x" +
                        std::to_string(height));
        if (path != "auto") ctx_.path = path_of(path);
        ctx_.pop_free = pop_free;
        if (threads > 0)
            threads_.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        auto gl = engine::platform::create_context(
            {.backend = headless ? engine::platform::Backend::headless : engine::platform::Backend::window,
             .width = width,
             .height = height,
             .title = "wires",
             .quiet = true});
        if (!gl) throw std::runtime_error("cannot create a GL context: " + gl.error().message);
        gl_ = std::move(gl).value();
        auto renderer = wire::render::WireRenderer::create();
        if (!renderer)
            throw std::runtime_error("cannot create the wire renderer: " + renderer.error().message);
        renderer_ = std::move(renderer).value();
        if (path == "auto") ctx_.path = renderer_.preferred_path();
        const engine::platform::Extent size = gl_->framebuffer_size();
        ctx_.viewport_width_px = size.width;
        ctx_.viewport_height_px = size.height;
        ctx_.camera.aspect = static_cast<float>(size.width) / static_cast<float>(size.height);
        ctx_.on_error = [this](const wire::systems::ErrorReport& e) { errors_.push_back(e); };
        wire::systems::install(schedule_, ctx_);
    }
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;
    /// Several runtimes may live in one process, each with its own context: the renderer's GL objects are
    /// deleted with this runtime's context current.
    ~Runtime() { gl_->make_current(); }
    [[nodiscard]] wire::UploadPath path() const { return ctx_.path; }

    Entity spawn(const DoubleArray& positions, const std::optional<IdArray>& ids,
                 const std::optional<FloatArray>& stretch, const std::optional<FloatArray>& radii,
                 float radius_m, uint32_t material, const std::string& spline, bool closed, bool caps,
                 uint32_t max_sides, float blend_s) {
        if (!(radius_m > 0.0f) || !std::isfinite(radius_m))
            value_error("radius: must be a positive finite number of metres, got " +
                        std::to_string(radius_m));
        if (material >= renderer_.materials().size())
            value_error("material " + std::to_string(material) + " does not exist (the renderer has " +
                        std::to_string(renderer_.materials().size()) + "; add_material() adds one)");
        wire::systems::Style style;
        style.radius_m = radius_m;
        style.material = material;
        style.spline = spline_of(spline);
        style.closed = closed;
        style.caps = caps;
        style.max_sides = max_sides;
        style.blend_s = blend_s;
        return wire::systems::spawn_wire(registry_, to_nodes(positions, ids, stretch, radii), style);
    }

    void set_nodes(Entity w, const DoubleArray& positions, const std::optional<IdArray>& ids,
                   const std::optional<FloatArray>& stretch, const std::optional<FloatArray>& radii) {
        check(w);
        // Positions only, on a wire without per-node arrays (the common physics step): written in place, so
        // the wire's node buffer is reused instead of a new one allocated every step.
        const wire::systems::Nodes& current = registry_.get<wire::systems::Nodes>(w);
        if (!ids && !stretch && !radii && current.ids.empty() && current.stretch.empty() &&
            current.radius_m.empty()) {
            check_positions(positions, "positions");  // before edit_nodes stamps the wire as changed
            read_positions(positions, "positions", wire::systems::edit_nodes(registry_, w).positions);
            return;
        }
        wire::systems::set_nodes(registry_, w, to_nodes(positions, ids, stretch, radii));
    }

    /// Positions of many wires at once: (W, N, 3), wire k gets positions[k] (ids and the other arrays
    /// unchanged). Written in place (edit_nodes), so a frame of 1,000 wires costs one Python call and no
    /// allocation.
    void set_positions(const std::vector<Entity>& wires, const DoubleArray& positions) {
        if (positions.ndim() != 3 || positions.shape(2) != 3 ||
            static_cast<std::size_t>(positions.shape(0)) != wires.size())
            value_error("positions: expected an array of shape (" + std::to_string(wires.size()) +
                        ", N, 3), one (N, 3) block per wire");
        for (Entity w : wires) check(w);
        const auto n = static_cast<std::size_t>(positions.shape(1));
        const double* p = positions.data();
        for (std::size_t k = 0; k < wires.size(); ++k) {
            const wire::systems::Nodes& current = registry_.get<wire::systems::Nodes>(wires[k]);
            if (current.size() != n &&
                (!current.ids.empty() || !current.stretch.empty() || !current.radius_m.empty()))
                value_error(wire::systems::describe_entity(wires[k]) + ": has " +
                            std::to_string(current.size()) +
                            " nodes with per-node arrays; set_positions gives " + std::to_string(n) +
                            " (use set_nodes to change the node count)");
        }
        for (std::size_t k = 0; k < wires.size(); ++k) {
            wire::WireNodes& nodes = wire::systems::edit_nodes(registry_, wires[k]);
            nodes.positions.resize(n);
            const double* src = p + 3 * n * k;
            for (std::size_t i = 0; i < n; ++i)
                nodes.positions[i] = {src[3 * i], src[3 * i + 1], src[3 * i + 2]};
        }
    }

    void destroy(Entity w) {
        check(w);
        registry_.destroy(w);
    }

    // ---- the bulk node stream (wire/render/node_stream.hpp): the renderer's wires, nodes path only ----

    wire::render::NodeStream& stream() {
        if (ctx_.path != wire::UploadPath::gpu_nodes)
            value_error("the node stream draws on the 'nodes' path; this runtime draws on '" +
                        std::string(wire::upload_path_name(ctx_.path)) + "'");
        wire::render::NodeStream& s = renderer_.node_stream();
        if (engine::Status st = s.usable(); !st) value_error(st.message);
        return s;
    }

    uint32_t stream_add(float radius_m, uint32_t material, const std::string& spline, bool closed, bool caps,
                        uint32_t max_sides) {
        if (material >= renderer_.materials().size())
            value_error("material " + std::to_string(material) + " does not exist (the renderer has " +
                        std::to_string(renderer_.materials().size()) + "; add_material() adds one)");
        const wire::SplineSettings settings = spline_of(spline);
        wire::render::StreamStyle style;
        style.radius_m = radius_m, style.material = material, style.max_sides = max_sides;
        style.kind = settings.kind, style.alpha = settings.alpha;
        style.closed = closed, style.caps = caps;
        gl_->make_current();
        auto w = stream().add(style);
        if (!w) value_error(w.error().message);
        return w->index;
    }

    void stream_remove(uint32_t wire) {
        gl_->make_current();
        stream().remove(wire::render::StreamWire{wire});
    }

    /// One frame of many streamed wires: positions (W, N, 3), float64 world positions, or float32 offsets from
    /// origins (W, 3) float64. Begins the stream's frame (the next render() draws it) and writes every wire in
    /// one call; refused wires (bad nodes) keep their last curve and raise WireError after the rest is written.
    std::size_t stream_nodes(const std::vector<uint32_t>& wires, const py::array& positions,
                             const std::optional<DoubleArray>& origins) {
        if (positions.ndim() != 3 || positions.shape(2) != 3 || static_cast<std::size_t>(positions.shape(0)) != wires.size())
            value_error("positions: expected an array of shape (" + std::to_string(wires.size()) +
                        ", N, 3), one (N, 3) block per wire");
        const auto n = static_cast<std::size_t>(positions.shape(1));
        std::vector<wire::render::StreamWire> handles(wires.size());
        for (std::size_t k = 0; k < wires.size(); ++k) handles[k].index = wires[k];
        gl_->make_current();
        wire::render::NodeStream& s = stream();
        if (engine::Status st = s.begin(wires.size() * n); !st) throw std::runtime_error(st.message);
        std::size_t written = 0;
        if (origins) {
            if (origins->ndim() != 2 || origins->shape(1) != 3 || static_cast<std::size_t>(origins->shape(0)) != wires.size())
                value_error("origins: expected an array of shape (" + std::to_string(wires.size()) + ", 3)");
            const auto offsets = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(positions);
            if (!offsets) value_error("positions: with origins, expected float32 offsets");
            std::vector<glm::dvec3> o(wires.size());
            for (std::size_t k = 0; k < o.size(); ++k) o[k] = {origins->at(k, 0), origins->at(k, 1), origins->at(k, 2)};
            py::gil_scoped_release release;
            written = s.write_many(handles, o, offsets.data(), n);
        } else {
            const auto xyz = DoubleArray::ensure(positions);
            if (!xyz) value_error("positions: expected float64 world positions");
            py::gil_scoped_release release;
            written = s.write_many(handles, xyz.data(), n);
        }
        const std::vector<wire::render::StreamError> errors = s.errors();
        if (!errors.empty()) {
            std::string message;
            for (const auto& e : errors) message += (message.empty() ? "" : "\n") + e.message;
            PyErr_SetString(g_wire_error, message.c_str());
            throw py::error_already_set();
        }
        return written;
    }

    void set_camera(const std::vector<double>& eye, const std::vector<double>& target,
                    const std::vector<double>& up, double fov_deg, double near_m, double far_m) {
        const glm::dvec3 e = vec3_of(eye, "eye"), t = vec3_of(target, "target"), u = vec3_of(up, "up");
        if (!(glm::length(t - e) > 0.0)) value_error("camera: eye and target must differ");
        if (!(glm::length(glm::cross(glm::normalize(t - e), u)) > 1e-9))
            value_error("camera: up must not be parallel to the view direction");
        if (!(fov_deg > 0.0 && fov_deg < 180.0)) value_error("camera: fov_deg must be in (0, 180)");
        if (!(near_m > 0.0 && far_m > near_m && std::isfinite(far_m)))
            value_error("camera: expected 0 < near < far (finite)");
        engine::scene::Camera& c = ctx_.camera;
        c.position = e;
        c.target = t;
        c.up = u;
        c.fov_y_rad = static_cast<float>(fov_deg * std::numbers::pi / 180.0);
        c.near_m = static_cast<float>(near_m);
        c.far_m = static_cast<float>(far_m);
    }

    /// Runs the wire systems once (curve, lod, rings, mesh, draw list). New wire errors raise WireError after
    /// the frame: the bad wire is skipped (it keeps its last valid curve), the rest of the scene was updated.
    void update(double dt_s) {
        if (!(dt_s >= 0.0) || !std::isfinite(dt_s))
            value_error("dt: must be a finite number of seconds >= 0");
        errors_.clear();
        schedule_.run(registry_, dt_s);
        if (!errors_.empty()) {
            std::string message;
            for (const wire::systems::ErrorReport& e : errors_)
                message += (message.empty() ? "" : "\n") + e.message;
            PyErr_SetString(g_wire_error, message.c_str());
            throw py::error_already_set();
        }
    }

    /// Draws the last update's draw list into the framebuffer and reads it back: (height, width, 4) uint8,
    /// row 0 the top of the image.
    py::array_t<uint8_t> render(const std::vector<double>& clear) {
        if (clear.size() != 4) value_error("clear: expected 4 numbers (r, g, b, a) in [0, 1]");
        gl_->make_current();
        gl_->begin_frame();
        engine::gfx::clear({clear[0], clear[1], clear[2], clear[3]});
        const auto t0 = std::chrono::steady_clock::now();
        wire::render::DrawSettings settings;
        settings.light = light_;
        drawn_ = renderer_.draw(ctx_.draw_list, ctx_.camera, settings);
        read_rings_done_ = false;
        rendered_ = true;
        render_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        engine::platform::Image image = engine::platform::read_pixels(*gl_);
        gl_->end_frame();
        py::array_t<uint8_t> out({py::ssize_t{image.height}, py::ssize_t{image.width}, py::ssize_t{4}});
        std::copy(image.rgba.begin(), image.rgba.end(), out.mutable_data());
        return out;
    }

    /// Pixel coordinates (x right, y down, pixel centres at +0.5) and NDC depth of world points, (N, 3) ->
    /// (N, 3); points behind the eye get NaN.
    py::array_t<double> project(const DoubleArray& points) const {
        std::vector<glm::dvec3> p;
        read_positions(points, "points", p);
        const glm::dmat4 clip_from_rel(ctx_.camera.clip_from_relative());  // offsets from the eye: any distance
        py::array_t<double> out({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
        double* o = out.mutable_data();
        for (std::size_t i = 0; i < p.size(); ++i) {
            const glm::dvec4 c = clip_from_rel * glm::dvec4(p[i] - ctx_.camera.position, 1.0);
            const bool front = c.w > 0.0;
            const double nan = std::numeric_limits<double>::quiet_NaN();
            o[3 * i] = front ? (c.x / c.w * 0.5 + 0.5) * ctx_.viewport_width_px : nan;
            o[3 * i + 1] = front ? (0.5 - c.y / c.w * 0.5) * ctx_.viewport_height_px : nan;
            o[3 * i + 2] = front ? c.z / c.w : nan;
        }
        return out;
    }

    py::object rings(Entity w) {
        check(w);
        if (ctx_.path == wire::UploadPath::gpu_nodes) {
            // The GPU computes them when render() draws: read back once per drawn frame.
            if (!rendered_)
                throw std::runtime_error("rings: on the 'nodes' path the GPU computes the rings when render() draws; "
                                         "call render() first");
            if (!read_rings_done_) {
                gl_->make_current();
                if (engine::Status st = renderer_.read_drawn_rings(read_rings_); !st)
                    throw std::runtime_error("rings: " + st.message);
                read_rings_done_ = true;
            }
            for (const wire::render::DrawnRings& d : read_rings_) {
                if (d.wire_id == engine::ecs::to_integral(w)) return rings_dict(d.rings);
            }
            return py::none();  // culled
        }
        if (!wire::systems::wire_ring_set(registry_, w, ring_set_)) return py::none();
        return rings_dict(ring_set_);
    }

    py::object error(Entity w) {
        check(w);
        const wire::systems::WireError* e = wire::systems::wire_error(registry_, w);
        if (e == nullptr) return py::none();
        return py::str(e->message);
    }

    py::dict stats() const {
        const wire::systems::RunStats& s = ctx_.stats;
        py::dict d;
        d["wires"] = s.wires;
        d["visible_wires"] = s.visible_wires;
        d["culled_wires"] = s.culled_wires;
        d["curves_built"] = s.curves_built;
        d["rings"] = s.rings;
        d["vertices"] = s.vertices;
        d["errors"] = s.errors;
        py::dict systems;
        double total = 0.0;
        for (const engine::ecs::SystemStats& st : schedule_.stats()) {
            systems[py::str(st.name)] = st.last_ms;
            total += st.last_ms;
        }
        d["systems_ms"] = systems;
        d["systems_total_ms"] = total;
        d["render_ms"] = render_ms_;
        d["drawn_vertices"] = drawn_.vertices;
        d["drawn_triangles"] = drawn_.triangles;
        d["bytes_uploaded"] = drawn_.bytes_uploaded;
        return d;
    }

    std::size_t memory(std::optional<Entity> w) {
        const wire::systems::WireMemory m = w ? (check(*w), wire::systems::wire_memory(registry_, *w))
                                              : wire::systems::wire_memory(registry_);
        return m.visible_bytes + m.culled_bytes + m.nodes_bytes;
    }

    uint32_t add_material(const std::vector<double>& tint) {
        const glm::dvec3 t = vec3_of(tint, "tint");
        gl_->make_current();
        return renderer_.add_material({.tint = glm::vec3(t)});
    }

    double tolerance_px() const { return ctx_.lod.tolerance_px > 0.0 ? ctx_.lod.tolerance_px : 0.5; }
    void set_tolerance_px(double px) {
        if (!(px > 0.0) || !std::isfinite(px))
            value_error("lod_tolerance_px: must be a positive number of pixels");
        ctx_.lod.tolerance_px = px;
    }
    std::pair<int, int> size() const {
        const engine::platform::Extent e = gl_->framebuffer_size();
        return {e.width, e.height};
    }
    bool headless() const { return gl_->headless(); }
    std::string gl_renderer() const { return gl_->gl_renderer(); }
    bool should_close() {
        gl_->poll_events();
        return gl_->should_close();
    }
    std::size_t wire_count() const { return registry_.alive(); }

private:
    void check(Entity w) const {
        if (!registry_.valid(w) || registry_.try_get<wire::systems::Nodes>(w) == nullptr)
            value_error(wire::systems::describe_entity(w) + " is not a live wire of this runtime");
    }

    // Destroyed in reverse order: the renderer's GL objects go while the context still exists.
    std::optional<tbb::global_control> threads_;
    std::unique_ptr<engine::platform::Context> gl_;
    wire::render::WireRenderer renderer_;
    engine::ecs::Registry registry_;
    engine::ecs::Schedule schedule_;
    wire::systems::WireContext ctx_;
    std::vector<wire::systems::ErrorReport> errors_;
    wire::RingSet ring_set_;
    std::vector<wire::render::DrawnRings> read_rings_;  ///< the nodes path: the last render()'s, read back
    bool read_rings_done_ = false, rendered_ = false;
    wire::render::Light light_{.to_light = {0.3f, 1.0f, 0.4f}, .ambient = 0.35f, .specular = 0.25f};
    wire::render::DrawStats drawn_{};
    double render_ms_ = 0.0;
};

/// The rings `wiretool mesh` makes of one wire (wire::WirePipeline with wire_io's defaults: automatic spline,
/// 8 rings per segment unless tolerance_m is given).
py::dict mesh_rings(const DoubleArray& positions, const std::optional<IdArray>& ids,
                    const std::optional<FloatArray>& stretch, const std::optional<FloatArray>& radii,
                    std::optional<double> radius_m, const std::string& spline, bool closed,
                    std::optional<uint32_t> rings_per_segment, std::optional<double> tolerance_m) {
    wire::io::WireSpec spec;
    spec.spline_type = spline;
    spec.closed = closed;
    spec.radius_m = radius_m;
    wire::io::SettingsOverrides overrides;
    overrides.rings_per_segment = rings_per_segment;
    overrides.tolerance_m = tolerance_m;
    wire::PipelineSettings settings;
    if (engine::Status st = wire::io::resolve_settings(spec, overrides, settings); !st.ok())
        value_error(st.message);
    wire::WirePipeline pipeline;
    if (engine::Status st = pipeline.update(to_nodes(positions, ids, stretch, radii), settings); !st.ok()) {
        PyErr_SetString(g_wire_error, st.message.c_str());
        throw py::error_already_set();
    }
    return rings_dict(pipeline.rings());
}

}  // namespace

PYBIND11_MODULE(wires, m) {
    m.doc() =
        "Wire rendering runtime: wires from numpy node arrays, drawn by the C++ wire systems and renderer";
    // The project's version (CMakeLists.txt project(VERSION)), the one the CMake package and the wheel carry.
    m.attr("__version__") = WIRES_VERSION;
    // WireError(ValueError): a wire's nodes rejected by the runtime, with its message (wire, node, problem).
    g_wire_error =
        PyErr_NewExceptionWithDoc("wires.WireError",
                                  "A wire's nodes were rejected by the runtime (the message names the "
                                  "wire entity, the node and the problem).",
                                  PyExc_ValueError, nullptr);
    if (g_wire_error == nullptr) throw py::error_already_set();
    m.attr("WireError") = py::handle(g_wire_error);

    py::class_<Entity>(m, "Wire", "Handle of a wire entity (wire entity N in messages)")
        .def_property_readonly("id", [](Entity e) { return engine::ecs::to_integral(e); })
        .def("__int__", [](Entity e) { return engine::ecs::to_integral(e); })
        .def("__eq__", [](Entity a, Entity b) { return a == b; })
        .def("__hash__", [](Entity e) { return engine::ecs::to_integral(e); })
        .def("__repr__", [](Entity e) { return "<wires.Wire " + wire::systems::describe_entity(e) + ">"; });

    py::class_<Runtime>(m, "Runtime",
                        "A scene: GL context (headless EGL or a window), wire renderer, ECS systems")
        .def(py::init<int, int, bool, const std::string&, int, bool>(), py::arg("width") = 1280,
             py::arg("height") = 720, py::arg("headless") = true, py::arg("path") = "auto",
             py::arg("threads") = 0, py::arg("pop_free") = true,
             "path: 'auto' (the default: 'nodes' where the GL context has compute shaders, else 'cpu'; logged on "
             "stderr), 'nodes' (nodes only: curve, LOD and rings computed on the GPU), 'cpu' (meshes: the portable "
             "reference; 'gpu', retired, draws on 'nodes' with a DeprecationWarning); threads: worker threads "
             "of the systems (0: all cores)")
        .def("spawn", &Runtime::spawn, py::arg("positions"), py::arg("ids") = py::none(),
             py::arg("stretch") = py::none(), py::arg("radii") = py::none(), py::arg("radius") = 0.01f,
             py::arg("material") = 0u, py::arg("spline") = "auto", py::arg("closed") = false,
             py::arg("caps") = true, py::arg("max_sides") = 0u, py::arg("blend_s") = 0.0f,
             "A new wire from (N, 3) node positions in metres; ids (stable across updates), stretch and "
             "per-node radii "
             "optional. Bad nodes are reported by the next update().")
        .def("set_nodes", &Runtime::set_nodes, py::arg("wire"), py::arg("positions"),
             py::arg("ids") = py::none(), py::arg("stretch") = py::none(), py::arg("radii") = py::none(),
             "Replaces a wire's nodes (what the physics computed this step)")
        .def("set_positions", &Runtime::set_positions, py::arg("wires"), py::arg("positions"),
             "Positions of many wires in one call: positions has shape (len(wires), N, 3)")
        .def("destroy", &Runtime::destroy, py::arg("wire"))
        .def("stream_add", &Runtime::stream_add, py::arg("radius") = 0.01f, py::arg("material") = 0u,
             py::arg("spline") = "auto", py::arg("closed") = false, py::arg("caps") = true, py::arg("max_sides") = 0u,
             "A wire of the bulk node stream (the 'nodes' path): an int handle; its nodes come from stream_nodes()")
        .def("stream_remove", &Runtime::stream_remove, py::arg("wire"))
        .def("stream_nodes", &Runtime::stream_nodes, py::arg("wires"), py::arg("positions"),
             py::arg("origins") = py::none(),
             "This frame's nodes of many streamed wires in one call, written straight into the renderer's mapped "
             "memory: positions (len(wires), N, 3) float64 world metres, or float32 offsets from origins "
             "(len(wires), 3). The next render() draws them beside the ECS wires. Bad nodes raise WireError naming "
             "the wire and node after the rest is written (those wires keep their last curve).")
        .def("set_camera", &Runtime::set_camera, py::arg("eye"), py::arg("target"),
             py::arg("up") = std::vector<double>{0.0, 1.0, 0.0}, py::arg("fov_deg") = 60.0,
             py::arg("near") = 0.1, py::arg("far") = 1000.0)
        .def_property("lod_tolerance_px", &Runtime::tolerance_px, &Runtime::set_tolerance_px)
        .def("add_material", &Runtime::add_material, py::arg("tint"),
             "Adds a material (linear RGB tint of the weave texture); returns its index. Material 0 is "
             "copper.")
        .def("update", &Runtime::update, py::arg("dt") = 1.0 / 60.0,
             "Runs the wire systems once; raises WireError naming the wire and node of any new bad input")
        .def("render", &Runtime::render, py::arg("clear") = std::vector<double>{0.10, 0.10, 0.12, 1.0},
             "Draws the last update and returns the image, shape (height, width, 4), uint8 RGBA, row 0 at "
             "the top")
        .def_static(
            "save_png",
            [](const std::string& path,
               const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& img) {
                if (img.ndim() != 3 || img.shape(2) != 4)
                    value_error("image: expected shape (height, width, 4) uint8");
                engine::platform::Image image{
                    .width = static_cast<int>(img.shape(1)),
                    .height = static_cast<int>(img.shape(0)),
                    .rgba = std::vector<uint8_t>(img.data(), img.data() + img.size())};
                if (auto st = engine::platform::write_png(path, image); !st)
                    throw std::runtime_error(path + ": " + st.message);
            },
            py::arg("path"), py::arg("image"))
        .def("project", &Runtime::project, py::arg("points"),
             "(N, 3) world points -> (N, 3): pixel x, pixel y (0 at the top), NDC depth; NaN behind the eye")
        .def("rings", &Runtime::rings, py::arg("wire"),
             "The wire's current rings as numpy arrays (centres, tangents, normals, binormals, radius, u, "
             "segment, t); "
             "None while it is culled or not updated yet. On the 'nodes' path: the rings the GPU computed and the "
             "last render() drew, read back (an error before the first render())")
        .def("error", &Runtime::error, py::arg("wire"), "The wire's current error message, or None")
        .def_property_readonly("stats", &Runtime::stats)
        .def("memory", &Runtime::memory, py::arg("wire") = py::none(),
             "Bytes the wire systems hold for one wire (or all), nodes included (wire::systems::wire_memory)")
        .def_property_readonly("size", &Runtime::size)
        .def_property_readonly("headless", &Runtime::headless)
        .def_property_readonly("gl_renderer", &Runtime::gl_renderer)
        .def_property_readonly(
            "path", [](const Runtime& r) { return std::string(wire::upload_path_name(r.path())); },
            "The upload path it draws with: 'nodes' or 'cpu' (with path='auto', what the context allows)")
        .def_property_readonly("wire_count", &Runtime::wire_count)
        .def("should_close", &Runtime::should_close, "Window: polls events; true once the user closed it");

    m.def("mesh_rings", &mesh_rings, py::arg("positions"), py::arg("ids") = py::none(),
          py::arg("stretch") = py::none(), py::arg("radii") = py::none(), py::arg("radius") = py::none(),
          py::arg("spline") = "auto", py::arg("closed") = false, py::arg("rings_per_segment") = py::none(),
          py::arg("tolerance_m") = py::none(),
          "The rings `wiretool mesh --csv` writes for one wire (fixed rings per segment, no camera)");
}
