// From a parsed wire (WireSpec) to what the wire pipeline takes: nodes and settings.
#include <wire/io/wire_json.hpp>

namespace wire::io {

Status resolve_settings(const WireSpec& spec, const SettingsOverrides& o, PipelineSettings& out) {
    PipelineSettings s;  // defaults
    // Default: the automatic spline (the best measured method, docs/speed_vs_error.md); an alpha given without
    // a type means Catmull-Rom with that alpha.
    const char* fallback = (o.alpha || spec.alpha) ? "catmull-rom" : "auto";
    const std::string type = o.spline_type ? *o.spline_type : spec.spline_type.value_or(fallback);
    if (type == "uniform" || type == "centripetal" || type == "chordal" || type == "catmull-rom") {
        s.spline.kind = SplineKind::catmull_rom;
        const double implied = type == "uniform" ? 0.0 : type == "chordal" ? 1.0 : 0.5;
        s.spline.alpha = o.alpha ? *o.alpha : o.spline_type ? implied : spec.alpha.value_or(implied);
    } else if (type == "c2") {
        s.spline.kind = SplineKind::c2;
    } else if (type == "auto" || type == "automatic") {
        s.spline.kind = SplineKind::automatic;
    } else if (type == "linear") {
        s.spline.kind = SplineKind::linear;
    } else {
        return Status::error("unknown spline type '" + type +
                             "' (expected uniform, centripetal, chordal, catmull-rom, c2, auto or linear)");
    }
    if (o.alpha && s.spline.kind != SplineKind::catmull_rom)
        return Status::error("--alpha applies to uniform/centripetal/chordal/catmull-rom, not '" + type + "'");
    s.spline.tension = o.tension ? *o.tension : spec.tension.value_or(0.0);
    s.spline.bias = spec.bias.value_or(0.0);
    s.spline.continuity = spec.continuity.value_or(0.0);
    s.spline.curvature_tension = spec.curvature_tension.value_or(!spec.physics.empty());
    s.spline.closed = spec.closed.value_or(false);
    if (spec.radius_m) s.spline.radius_m = static_cast<float>(*spec.radius_m);
    if (o.tolerance_m) {
        s.tessellate.tolerance_m = *o.tolerance_m;
    } else {
        s.tessellate.rings_per_segment = o.rings_per_segment.value_or(default_rings_per_segment);
    }
    s.tube.sides = o.sides ? *o.sides : spec.sides ? static_cast<uint32_t>(*spec.sides) : default_sides;
    s.tube.caps = o.caps ? *o.caps : spec.caps.value_or(true);
    out = s;
    return Status::success();
}

WireNodes to_wire_nodes(const WireSpec& spec) {
    WireNodes n;
    n.positions = spec.positions;
    n.ids = spec.ids;
    n.stretch = spec.stretch;
    n.radius_m.resize(spec.radius.size());
    for (std::size_t i = 0; i < spec.radius.size(); ++i) n.radius_m[i] = spec.radius[i] > 0 ? spec.radius[i] : 0.0f;
    for (const NodePhysics& p : spec.physics) {
        n.theta_rad.push_back(p.theta);
        n.iz_m4.push_back(p.Iz);
        n.length_m.push_back(p.L);
        n.delta_length_m.push_back(p.dL);
        n.area_m2.push_back(p.A);
    }
    for (const glm::dvec3& tcb : spec.tcb) {
        n.kb_tension.push_back(static_cast<float>(tcb.x));
        n.kb_bias.push_back(static_cast<float>(tcb.y));
        n.kb_continuity.push_back(static_cast<float>(tcb.z));
    }
    return n;
}

}  // namespace wire::io
