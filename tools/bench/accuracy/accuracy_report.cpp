// The accuracy bench's report (accuracy_report.hpp).
#include "bench/accuracy/accuracy_report.hpp"

#include "bench/accuracy/methods.hpp"
#include "wiretool/commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace wiretool::bench {
namespace {

std::vector<std::string> to_cells(const Row& r) {
    return {r.scene,
            r.method,
            num(r.tolerance_px),
            num(r.rings),
            num(r.sides),
            num(r.vertices),
            num(r.bytes_cpu),
            num(r.bytes_gpu),
            num(r.ns_per_vertex),
            num(r.us_cpu),
            num(r.us_gpu),
            num(r.world_m),
            num(r.screen_px),
            num(r.twist_deg),
            num(r.pop_m),
            num(r.pop_blended_m),
            num(r.pop_blended_m)};  // max_pop_remedy_m: the alias of max_pop_blended_m, for one release
}

const Row* find_row(const std::vector<Row>& rows, const std::string& scene, const std::string& method,
                    double tol) {
    for (const Row& r : rows)
        if (r.scene == scene && r.method == method && std::abs(r.tolerance_px - tol) < 1e-12) return &r;
    return nullptr;
}

/// Writes the data and script and runs gnuplot. Returns a sentence for accuracy.md.
std::string plot(const Options& o, const std::vector<Row>& rows, const FamilyResults& families) {
    const std::filesystem::path dat = o.out_dir / "speed_vs_error.dat";
    const std::filesystem::path gp = o.out_dir / "speed_vs_error.gp";
    const std::filesystem::path png = o.out_dir / "speed_vs_error.png";
    struct Panel {
        std::string scene, title, xlabel;
        bool twist;
        std::vector<std::string> methods;
    };
    const std::vector<std::string> splines = {"linear", "uniform", "centripetal",      "chordal",
                                              "c2",     "auto",    "curvature_tension"};
    const std::vector<Panel> panels = {
        {"catenary", "catenary 20 m, 16 nodes", "max world error against the exact catenary (m)", false,
         splines},
        {"random_walk", "smooth random curve, 40 nodes", "max world error against the exact curve (m)", false,
         splines},
        {"helix",
         "helix, 3 turns: frame methods",
         "max twist error against the RMF (degrees)",
         true,
         {"centripetal", "centripetal+rotation", "centripetal+projection"}},
    };
    std::string data, script;
    const std::string family_panel = family_plot_panel(o.out_dir / "families.dat", families);
    script += family_panel.empty() ? "set terminal png size 1800,620 font \",11\" noenhanced\n"
                                   : "set terminal png size 1800,1240 font \",11\" noenhanced\n";
    script +=
        "set output '" + png.string() + "'\nset multiplot layout " + (family_panel.empty() ? "1,3" : "2,2") +
        " title \"wiretool bench: time per wire "
        "against error, one marker per LOD tolerance (0.1, 0.25, 0.5, 1, 2 px; larger tolerance = fewer rings"
        " = less time)\"\n";
    script +=
        "set logscale xy\nset grid\nset key top right font \",9\"\nset ylabel \"CPU time per wire, "
        "curve+lod+rings+mesh (us)\"\n";
    int block = 0;
    bool any = false;
    for (const Panel& p : panels) {
        std::string plots;
        for (const std::string& m : p.methods) {
            std::string lines;
            for (double tol : kTolerancesPx) {
                const Row* r = find_row(rows, p.scene, m, tol);
                if (!r) continue;
                const double x = std::max(p.twist ? r->twist_deg : r->world_m, 1e-12);
                lines += num(x, 6) + " " + num(r->us_cpu, 6) + " " + num(tol) + "\n";
            }
            if (lines.empty()) continue;
            data += "# " + p.scene + " " + m + "\n" + lines + "\n\n";
            plots += std::string(plots.empty() ? "plot " : ", ") + "'" + dat.string() + "' index " +
                     std::to_string(block++) + " using 1:2 with linespoints pointsize 1.3 title \"" + m +
                     "\"";
            if (m == "centripetal")
                plots += ", '' index " + std::to_string(block - 1) +
                         " using 1:2:(sprintf(\"%g px\",$3)) with labels offset 0,-1 font \",8\" notitle";
        }
        if (plots.empty()) {
            script += "set multiplot next\n";  // nothing for this panel (scene not selected)
            continue;
        }
        any = true;
        script += "set title \"" + p.title + "\"\nset xlabel \"" + p.xlabel + "\"\n" + plots + "\n";
    }
    script += family_panel;
    any = any || !family_panel.empty();
    script += "unset multiplot\n";
    if (!any) return "Plot skipped: none of its scenes (catenary, random_walk, helix) was run.";
    if (!write_text(dat, data) || !write_text(gp, script)) return "Plot skipped: cannot write its data.";
    if (std::system("gnuplot --version > /dev/null 2>&1") != 0)
        return "Plot skipped: gnuplot is not installed (tools/setup.sh installs gnuplot-nox); data and "
               "script are in "
               "speed_vs_error.dat/.gp.";
    const std::string cmd =
        "gnuplot '" + gp.string() + "' > '" + (o.out_dir / "gnuplot.log").string() + "' 2>&1";
    if (std::system(cmd.c_str()) != 0 || !std::filesystem::exists(png))
        return "Plot failed: see gnuplot.log (script speed_vs_error.gp).";
    return "Plot: speed_vs_error.png (data speed_vs_error.dat, script speed_vs_error.gp).";
}

}  // namespace

int write_accuracy_report(const Options& o, const std::vector<ReferenceScene>& scenes,
                          const std::vector<Row>& rows, const FamilyResults& families,
                          std::string& plot_note) {
    Table csv;
    csv.header = {"scene",
                  "method",
                  "tolerance_px",
                  "rings",
                  "sides",
                  "vertices",
                  "bytes_cpu_mesh",
                  "bytes_gpu_nodes",
                  "ns_per_vertex",
                  "us_per_wire_cpu_mesh",
                  "us_per_wire_gpu_nodes",
                  "max_world_error_m",
                  "max_screen_error_px",
                  "max_twist_deg",
                  "max_pop_m",
                  "max_pop_blended_m",
                  "max_pop_remedy_m"};
    for (const Row& r : rows) csv.add(to_cells(r));
    if (!csv.write_csv(o.out_dir / "accuracy.csv")) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "accuracy.csv").c_str());
        return exit_failure;
    }

    plot_note = plot(o, rows, families);
    std::string md = "# wiretool bench: speed against error\n\n";
    md +=
        "One wire per scene, seen whole by a 1920x1080, 60-degree camera; every spline method (frames by "
        "double "
        "reflection) plus centripetal with the rotation and projection frame baselines; LOD tolerances 0.1, "
        "0.25, "
        "0.5, 1 and 2 px. Columns: rings, radial sides and tube vertices the LOD chose; bytes one frame "
        "uploads "
        "(cpu-mesh: vertices + indices + draw record + command; gpu-nodes: the first frame's 64-byte header, "
        "packed nodes and list entry, independent of the tolerance); CPU time of curve + lod + rings + mesh "
        "(cpu-mesh) or of packing the nodes (gpu-nodes; churn: the pop-free stage, which runs on the CPU on both "
        "paths) per wire, median of 3 trials, and per vertex; `max_world_error_m`: largest distance from the "
        "drawn centre polyline "
        "to the exact curve (spline error plus tessellation error); `max_screen_error_px`: largest pixel "
        "distance "
        "from the rendered curve to the drawn polyline; `max_twist_deg`: largest angle between a ring's "
        "normal "
        "and the rotation-minimizing frame of the same curve at the same point (double reflection at 64 "
        "steps "
        "per ring interval); `max_pop_m`/`max_pop_blended_m`: largest displacement between consecutive frames "
        "without/with the pop-free blend, for one node inserted exactly on the curve then one removed "
        "(churn: every event of the run; `max_pop_remedy_m` repeats `max_pop_blended_m` under its old name, for one "
        "release). Pops do not depend on the tolerance.\n\n";
    md += "Scenes:\n\n";
    for (const ReferenceScene& s : scenes) md += "- `" + s.name + "`: " + s.description + "\n";
    md += "\n" + plot_note + "\n\n";

    // Key figures.
    md += "## Key figures (tolerance 0.5 px unless said)\n\n";
    char buf[512];
    for (const char* scene : {"catenary", "stretched_bend", "hairpin", "random_walk", "helix"}) {
        if (!find_row(rows, scene, "linear", 0.5)) continue;
        md += std::string("- `") + scene + "` world error (m) at 0.1 px:";
        for (const Method& m : methods()) {
            if (m.frames != wire::FrameMethod::double_reflection) continue;
            const Row* r = find_row(rows, scene, m.name, 0.1);
            std::snprintf(buf, sizeof buf, " %s %.3g;", m.name.c_str(), r ? r->world_m : NAN);
            md += buf;
        }
        md += "\n";
    }
    if (const Row* dr = find_row(rows, "helix", "centripetal", 0.5)) {
        const Row* rot = find_row(rows, "helix", "centripetal+rotation", 0.5);
        const Row* proj = find_row(rows, "helix", "centripetal+projection", 0.5);
        std::snprintf(buf, sizeof buf,
                      "- twist error on the helix at equal rings (%zu rings): double reflection %.3g deg, "
                      "rotation %.3g "
                      "deg (%.0fx), projection %.3g deg (%.0fx)\n",
                      dr->rings, dr->twist_deg, rot ? rot->twist_deg : NAN,
                      rot && dr->twist_deg > 0 ? rot->twist_deg / dr->twist_deg : NAN,
                      proj ? proj->twist_deg : NAN,
                      proj && dr->twist_deg > 0 ? proj->twist_deg / dr->twist_deg : NAN);
        md += buf;
    }
    for (const char* scene : {"churn", "catenary"}) {
        if (!find_row(rows, scene, "centripetal", 0.5)) continue;
        md += std::string("- `") + scene + "` largest pop, unblended -> blended (m):";
        for (const Method& m : methods()) {
            if (m.frames != wire::FrameMethod::double_reflection) continue;
            const Row* r = find_row(rows, scene, m.name, 0.5);
            std::snprintf(buf, sizeof buf, " %s %.3g -> %.3g;", m.name.c_str(), r->pop_m, r->pop_blended_m);
            md += buf;
        }
        md += "\n";
    }
    md += "\n" + write_family_outputs(o, families);
    md += "\n## All rows\n\n" + csv.markdown();
    md += "\nThe DESIGN §5 hard cases: see stability.md.\n";
    if (!write_text(o.out_dir / "accuracy.md", md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "accuracy.md").c_str());
        return exit_failure;
    }
    return exit_ok;
}

}  // namespace wiretool::bench
