// Wire JSON reader: nlohmann::json parsing plus form checks with specific, located messages.
#include <wire/io/wire_json.hpp>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_set>

namespace wire::io {
namespace {

using nlohmann::json;

/// Thrown inside the parser only, caught at its boundary and turned into a Status.
struct ParseError {
    std::string message;
    int node = -1;
};

struct Where {
    std::string source;
    int frame = -1;  ///< -1: the file has no "frames"
    int wire = -1;   ///< -1: the file is a single wire
    int node = -1;

    [[nodiscard]] std::string str() const {
        std::string s = source;
        if (frame >= 0) s += ": frame " + std::to_string(frame);
        if (wire >= 0) s += (frame >= 0 ? ", wire " : ": wire ") + std::to_string(wire);
        if (node >= 0) s += (frame >= 0 || wire >= 0 ? ", node " : ": node ") + std::to_string(node);
        return s;
    }
    [[noreturn]] void fail(const std::string& what) const { throw ParseError{str() + ": " + what, node}; }
};

const char* type_name(const json& j) { return j.type_name(); }

// A value as the user wrote it: %.9g, not std::to_string's fixed 6 decimals (which shows -1e-9 as -0.000000).
std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

double finite_number(const json& j, const Where& at, const std::string& what) {
    if (!j.is_number()) at.fail(what + " must be a number, got " + type_name(j));
    const double v = j.get<double>();
    if (!std::isfinite(v)) at.fail(what + " is not finite (" + number(v) + ")");
    return v;
}

bool boolean(const json& j, const Where& at, const std::string& what) {
    if (!j.is_boolean()) at.fail(what + " must be true or false, got " + type_name(j));
    return j.get<bool>();
}

glm::dvec3 point(const json& j, const Where& at) {
    if (!j.is_array()) at.fail("position must be an array [x, y, z], got " + std::string(type_name(j)));
    if (j.size() != 3) at.fail("position has " + std::to_string(j.size()) + " coordinates, expected 3");
    static const char* axis[3] = {"x", "y", "z"};
    glm::dvec3 p;
    for (int k = 0; k < 3; ++k) p[k] = finite_number(j[k], at, std::string("coordinate ") + axis[k]);
    return p;
}

void check_keys(const json& obj, std::initializer_list<const char*> allowed, const Where& at, const char* what) {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool known = false;
        for (const char* k : allowed) known = known || it.key() == k;
        if (!known) at.fail(std::string("unknown key '") + it.key() + "' in " + what);
    }
}

void parse_spline(const json& s, WireSpec& w, const Where& at) {
    if (s.is_string()) {
        w.spline_type = s.get<std::string>();
        return;
    }
    if (!s.is_object()) at.fail("\"spline\" must be an object or a type name, got " + std::string(type_name(s)));
    check_keys(s, {"type", "alpha", "tension", "bias", "continuity", "curvature_tension"}, at, "\"spline\"");
    if (s.contains("type")) {
        if (!s["type"].is_string()) at.fail("spline type must be a string");
        w.spline_type = s["type"].get<std::string>();
    }
    if (s.contains("alpha")) w.alpha = finite_number(s["alpha"], at, "spline alpha");
    if (s.contains("tension")) w.tension = finite_number(s["tension"], at, "spline tension");
    if (s.contains("bias")) w.bias = finite_number(s["bias"], at, "spline bias");
    if (s.contains("continuity")) w.continuity = finite_number(s["continuity"], at, "spline continuity");
    if (s.contains("curvature_tension")) w.curvature_tension = boolean(s["curvature_tension"], at, "curvature_tension");
}

WireSpec parse_wire(const json& j, Where at) {
    if (!j.is_object()) at.fail("a wire must be an object with \"nodes\", got " + std::string(type_name(j)));
    check_keys(j, {"radius", "closed", "caps", "spline", "sides", "nodes", "name"}, at, "wire");
    WireSpec w;
    if (j.contains("radius")) {
        const double r = finite_number(j["radius"], at, "radius");
        if (!(r > 0)) at.fail("radius must be positive, got " + number(r));
        w.radius_m = r;
    }
    if (j.contains("closed")) w.closed = boolean(j["closed"], at, "closed");
    if (j.contains("caps")) w.caps = boolean(j["caps"], at, "caps");
    if (j.contains("sides")) {
        if (!j["sides"].is_number_integer()) at.fail("sides must be an integer");
        const auto n = j["sides"].get<int64_t>();
        if (n < 3 || n > 1024) at.fail("sides must be in [3, 1024], got " + std::to_string(n));
        w.sides = static_cast<int>(n);
    }
    if (j.contains("spline")) parse_spline(j["spline"], w, at);
    if (!j.contains("nodes")) at.fail("missing \"nodes\"");
    const json& nodes = j["nodes"];
    if (!nodes.is_array()) at.fail("\"nodes\" must be an array, got " + std::string(type_name(nodes)));

    const std::size_t n = nodes.size();
    w.positions.reserve(n);
    w.ids.reserve(n);
    w.stretch.assign(n, 1.0f);
    w.radius.assign(n, -1.0f);
    bool any_id = false, any_physics = false, any_tcb = false;
    std::vector<bool> has_id(n, false);
    for (std::size_t i = 0; i < n; ++i) {
        Where node_at = at;
        node_at.node = static_cast<int>(i);
        const json& nj = nodes[i];
        if (nj.is_array()) {
            w.positions.push_back(point(nj, node_at));
            w.ids.push_back(static_cast<uint32_t>(i));
            continue;
        }
        if (!nj.is_object()) node_at.fail("a node must be [x, y, z] or {\"p\": [x, y, z], ...}, got " +
                                           std::string(type_name(nj)));
        check_keys(nj, {"p", "id", "stretch", "radius", "physics", "tension", "bias", "continuity"}, node_at, "node");
        if (!nj.contains("p")) node_at.fail("missing \"p\"");
        w.positions.push_back(point(nj["p"], node_at));
        if (nj.contains("id")) {
            const json& id = nj["id"];
            if (!id.is_number_integer() || id.get<int64_t>() < 0 ||
                id.get<int64_t>() > int64_t(std::numeric_limits<uint32_t>::max()))
                node_at.fail("id must be an integer in [0, 4294967295]");
            w.ids.push_back(static_cast<uint32_t>(id.get<int64_t>()));
            has_id[i] = true;
            any_id = true;
        } else {
            w.ids.push_back(static_cast<uint32_t>(i));
        }
        if (nj.contains("stretch")) {
            const double s = finite_number(nj["stretch"], node_at, "stretch");
            if (!(s > 0)) node_at.fail("stretch must be positive, got " + number(s));
            w.stretch[i] = static_cast<float>(s);
        }
        if (nj.contains("radius")) {
            const double r = finite_number(nj["radius"], node_at, "radius");
            if (!(r > 0)) node_at.fail("radius must be positive, got " + number(r));
            w.radius[i] = static_cast<float>(r);
        }
        if (nj.contains("physics")) {
            const json& ph = nj["physics"];
            if (!ph.is_object()) node_at.fail("physics must be an object {theta, Iz, L, dL, A}");
            check_keys(ph, {"theta", "Iz", "L", "dL", "A"}, node_at, "physics");
            if (!any_physics) w.physics.assign(n, NodePhysics{});
            any_physics = true;
            NodePhysics& p = w.physics[i];
            for (const char* key : {"theta", "Iz", "L", "dL", "A"})
                if (!ph.contains(key)) node_at.fail(std::string("physics lacks \"") + key + "\"");
            p.theta = finite_number(ph["theta"], node_at, "physics theta");
            p.Iz = finite_number(ph["Iz"], node_at, "physics Iz");
            p.L = finite_number(ph["L"], node_at, "physics L");
            p.dL = finite_number(ph["dL"], node_at, "physics dL");
            p.A = finite_number(ph["A"], node_at, "physics A");
            if (!(p.A > 0)) node_at.fail("physics A must be positive, got " + number(p.A));
        }
        if (nj.contains("tension") || nj.contains("bias") || nj.contains("continuity")) {
            if (!any_tcb) w.tcb.assign(n, glm::dvec3(0.0));
            any_tcb = true;
            if (nj.contains("tension")) w.tcb[i].x = finite_number(nj["tension"], node_at, "tension");
            if (nj.contains("bias")) w.tcb[i].y = finite_number(nj["bias"], node_at, "bias");
            if (nj.contains("continuity")) w.tcb[i].z = finite_number(nj["continuity"], node_at, "continuity");
        }
    }
    if (any_id) {
        // Ids key nodes across frames: either every node has one or none does, and they are unique.
        std::unordered_set<uint32_t> seen;
        for (std::size_t i = 0; i < n; ++i) {
            Where node_at = at;
            node_at.node = static_cast<int>(i);
            if (!has_id[i]) node_at.fail("has no \"id\" while other nodes of this wire do");
            if (!seen.insert(w.ids[i]).second) node_at.fail("id " + std::to_string(w.ids[i]) + " is used twice");
        }
    }
    return w;
}

FrameSpec parse_wire_list(const json& j, Where at) {
    FrameSpec f;
    if (!j.is_array()) at.fail("\"wires\" must be an array, got " + std::string(type_name(j)));
    for (std::size_t i = 0; i < j.size(); ++i) {
        Where w_at = at;
        w_at.wire = static_cast<int>(i);
        f.wires.push_back(parse_wire(j[i], w_at));
    }
    return f;
}

CameraSpec parse_camera(const json& j, Where at) {
    if (!j.is_object())
        at.fail("\"camera\" must be an object {\"eye\", \"target\", \"up\", \"fov_deg\"}, got " +
                std::string(type_name(j)));
    check_keys(j, {"eye", "target", "up", "fov_deg"}, at, "camera");
    auto vec = [&](const char* key) {
        const json& v = j[key];
        if (!v.is_array() || v.size() != 3)
            at.fail(std::string("camera ") + key + " must be an array [x, y, z]");
        glm::dvec3 p;
        static const char* axis[3] = {"x", "y", "z"};
        for (int k = 0; k < 3; ++k) p[k] = finite_number(v[k], at, std::string("camera ") + key + " " + axis[k]);
        return p;
    };
    CameraSpec c;
    for (const char* key : {"eye", "target"})
        if (!j.contains(key)) at.fail(std::string("camera lacks \"") + key + "\"");
    c.eye_m = vec("eye");
    c.target_m = vec("target");
    const glm::dvec3 view = c.target_m - c.eye_m;
    if (!(glm::length(view) > 0.0)) at.fail("camera eye and target must differ");
    if (j.contains("up")) {
        const glm::dvec3 up = vec("up");
        // Compared as unit vectors, so the check does not overflow for huge coordinates.
        if (!(glm::length(up) > 0.0) ||
            !(glm::length(glm::cross(glm::normalize(view), glm::normalize(up))) > 1e-6))
            at.fail("camera up must be non-zero and not parallel to target - eye");
        c.up = up;
    }
    if (j.contains("fov_deg")) {
        const double fov = finite_number(j["fov_deg"], at, "camera fov_deg");
        if (!(fov > 0.0 && fov < 180.0)) at.fail("camera fov_deg must be in (0, 180), got " + number(fov));
        c.fov_deg = fov;
    }
    return c;
}

}  // namespace

Status parse_wire_json(std::string_view text, const std::string& source, SceneSpec& out) {
    out.frames.clear();
    json root;
    try {
        root = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e999
        return Status::error(source + ": malformed JSON: " + e.what());
    }
    try {
        Where at{source};
        if (!root.is_object()) at.fail("the top level must be an object (a wire, {\"wires\": [...]} or "
                                       "{\"frames\": [...]}), got " + std::string(type_name(root)));
        if (root.contains("frames")) {
            check_keys(root, {"frames"}, at, "the top level");
            const json& frames = root["frames"];
            if (!frames.is_array() || frames.empty()) at.fail("\"frames\" must be a non-empty array");
            for (std::size_t k = 0; k < frames.size(); ++k) {
                Where f_at = at;
                f_at.frame = static_cast<int>(k);
                if (!frames[k].is_object() || !frames[k].contains("wires"))
                    f_at.fail("a frame must be an object {\"wires\": [...]}");
                check_keys(frames[k], {"wires", "camera"}, f_at, "a frame");
                out.frames.push_back(parse_wire_list(frames[k]["wires"], f_at));
                if (frames[k].contains("camera")) out.frames.back().camera = parse_camera(frames[k]["camera"], f_at);
                if (k > 0 && out.frames[k].wires.size() != out.frames[0].wires.size())
                    f_at.fail("has " + std::to_string(out.frames[k].wires.size()) + " wires but frame 0 has " +
                              std::to_string(out.frames[0].wires.size()) + " (wires are matched by position)");
            }
        } else if (root.contains("wires")) {
            check_keys(root, {"wires"}, at, "the top level");
            out.frames.push_back(parse_wire_list(root["wires"], at));
        } else {
            FrameSpec f;
            f.wires.push_back(parse_wire(root, at));
            out.frames.push_back(std::move(f));
        }
        if (out.frames.front().wires.empty()) at.fail("contains no wire");
    } catch (const ParseError& e) {
        out.frames.clear();
        return Status::error(e.message, e.node);
    } catch (const json::exception& e) {  // defensive: a type error we did not foresee
        out.frames.clear();
        return Status::error(source + ": " + e.what());
    }
    return Status::success();
}

Status load_wire_json(const std::string& path, SceneSpec& out) {
    out.frames.clear();
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error(path + ": cannot open: " + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) return Status::error(path + ": read failed");
    return parse_wire_json(text.str(), path, out);
}

}  // namespace wire::io
