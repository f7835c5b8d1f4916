// Debug panel with Dear ImGui (Debian's libimgui-dev: libimgui.a with the GLFW and OpenGL 3 backends).
// engine::platform hides the GLFW window, but its context is current on this thread, so
// glfwGetCurrentContext() finds it; ImGui's GLFW backend chains the engine's input callbacks.
#include "tunnel/debug_ui.hpp"

#include <engine/assets/subdivide.hpp>

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <cstdio>

namespace tunnel {

namespace {

class ImGuiUi final : public DebugUi {
public:
    explicit ImGuiUi(GLFWwindow* window) {
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;
        ImGui::StyleColorsDark();
        ImGui_ImplGlfw_InitForOpenGL(window, true);
        ImGui_ImplOpenGL3_Init("#version 450");
    }
    ~ImGuiUi() override {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }

    void draw(Level& level, double frame_ms, UiRequests& requests) override {
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(360, 0), ImGuiCond_FirstUseEver);
        ImGui::Begin("tunnel");
        LevelOptions& o = level.options();
        const LevelFrameStats& s = level.stats();
        ImGui::Text("%.2f ms/frame (%.0f fps)", frame_ms, ImGui::GetIO().Framerate);

        int spline = static_cast<int>(o.spline);
        const char* splines[] = {"Catmull-Rom (centripetal)", "C2 interpolating", "automatic", "linear"};
        if (ImGui::Combo("spline", &spline, splines, 4)) o.spline = static_cast<wire::SplineKind>(spline);
        float tolerance = static_cast<float>(o.lod_tolerance_px);
        if (ImGui::SliderFloat("LOD tolerance px", &tolerance, 0.1f, 8.0f, "%.2f",
                               ImGuiSliderFlags_Logarithmic))
            o.lod_tolerance_px = tolerance;
        int path = o.upload_path == wire::UploadPath::gpu_nodes ? 1 : 0;
        ImGui::RadioButton("cpu mesh", &path, 0);
        ImGui::SameLine();
        ImGui::RadioButton("gpu nodes", &path, 1);
        o.upload_path = path == 1 ? wire::UploadPath::gpu_nodes : wire::UploadPath::cpu_mesh;
        ImGui::Checkbox("wireframe (F1)", &o.wireframe);
        ImGui::SameLine();
        ImGui::Checkbox("pop-free", &o.pop_free);
        ImGui::Checkbox("animate bends (P)", &o.animate_bends);
        ImGui::SameLine();
        ImGui::Checkbox("rope sim", &o.simulate_ropes);
        ImGui::Checkbox("rope refine/coarsen", &o.adapt_ropes);
        bool free_camera = o.camera_mode == CameraMode::free;
        if (ImGui::Checkbox("free camera (Tab)", &free_camera))
            o.camera_mode = free_camera ? CameraMode::free : CameraMode::fly;
        float speed = static_cast<float>(o.flight_speed_mps);
        if (ImGui::SliderFloat("flight m/s", &speed, 0.0f, 10.0f)) o.flight_speed_mps = speed;
        float subdiv = static_cast<float>(o.subdivision_tolerance_px);
        if (ImGui::SliderFloat("subdiv tolerance px", &subdiv, 0.25f, 16.0f, "%.2f",
                               ImGuiSliderFlags_Logarithmic))
            o.subdivision_tolerance_px = subdiv;
        ImGui::SliderInt("max subdiv level", &o.max_subdivision_level, 0, engine::assets::kMaxSubdivisionLevel);
        ImGui::Checkbox("pieces", &o.draw_pieces);
        ImGui::SameLine();
        ImGui::Checkbox("wires", &o.draw_wires);
        if (ImGui::Button("screenshot (F12)")) requests.screenshot = true;

        if (ImGui::CollapsingHeader("systems (ms)", ImGuiTreeNodeFlags_DefaultOpen)) {
            for (const engine::ecs::SystemStats& st : level.system_stats())
                ImGui::Text("%-15s %7.3f  mean %7.3f", st.name.c_str(), st.last_ms, st.mean_ms);
        }
        if (ImGui::CollapsingHeader("counts", ImGuiTreeNodeFlags_DefaultOpen)) {
            ImGui::Text("wires %zu, drawn %zu, curves built %zu", s.wires, s.wires_drawn, s.curves_built);
            ImGui::Text("wire vertices %zu, triangles %zu, rings %zu", s.wire_vertices, s.wire_triangles,
                        s.rings);
            ImGui::Text("uploaded %.1f KiB (wires %.1f, segments %.1f)",
                        static_cast<double>(s.wire_bytes_uploaded + s.segment_bytes_uploaded) / 1024.0,
                        static_cast<double>(s.wire_bytes_uploaded) / 1024.0,
                        static_cast<double>(s.segment_bytes_uploaded) / 1024.0);
            ImGui::Text("tunnel triangles %zu, vertices %zu", s.piece_triangles, s.piece_vertices);
            ImGui::Text("pieces per level: %d %d %d %d %d", s.piece_levels[0], s.piece_levels[1],
                        s.piece_levels[2], s.piece_levels[3], s.piece_levels[4]);
            ImGui::Text("rope nodes %zu (+%d -%d this frame)", s.rope_nodes, s.nodes_inserted,
                        s.nodes_removed);
        }
        ImGui::End();
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
    bool wants_mouse() const override { return ImGui::GetIO().WantCaptureMouse; }
    bool wants_keyboard() const override { return ImGui::GetIO().WantCaptureKeyboard; }
    const char* kind() const override { return "Dear ImGui"; }
};

}  // namespace

std::unique_ptr<DebugUi> DebugUi::create(engine::platform::Context& context) {
    GLFWwindow* window = context.headless() ? nullptr : glfwGetCurrentContext();
    if (window == nullptr) return make_text_ui("stdout (no GLFW window for ImGui)");
    return std::make_unique<ImGuiUi>(window);
}

}  // namespace tunnel
