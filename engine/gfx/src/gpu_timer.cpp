// GpuTimer: a ring of GL query objects; results are read only when GL_QUERY_RESULT_AVAILABLE says so.
#include "engine/gfx/gpu_timer.hpp"

#include <epoxy/gl.h>

#include <cassert>
#include <chrono>
#include <deque>

namespace engine::gfx {

struct GpuTimer::State {
    struct Pending {
        GLuint query;
        uint64_t frame;
        std::chrono::steady_clock::time_point issued;
    };
    std::vector<GLuint> free_queries;
    std::vector<GLuint> all;
    std::deque<Pending> pending;  ///< oldest first
    uint64_t frames = 0;
    uint64_t skipped = 0;
    uint64_t rejected = 0;
    bool active = false;
    bool measuring = false;  ///< the active begin() got a query
    std::optional<Measurement> latest;

    ~State() {
        if (!all.empty()) glDeleteQueries(static_cast<GLsizei>(all.size()), all.data());
    }

    /// The result, or nothing when it is impossible: a pass cannot take longer on the GPU than the wall time
    /// from issuing it to reading it back (llvmpipe reports time since boot for a query begun while its
    /// rasterizer has no scene, e.g. around a clear alone).
    std::optional<Measurement> read(const Pending& p) {
        GLuint64 ns = 0;
        glGetQueryObjectui64v(p.query, GL_QUERY_RESULT, &ns);
        free_queries.push_back(p.query);
        const double wall_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - p.issued).count();
        const double ms = static_cast<double>(ns) * 1e-6;
        if (ms > wall_ms + 1.0) {
            ++rejected;
            return std::nullopt;
        }
        return Measurement{p.frame, ms};
    }
};

GpuTimer::GpuTimer() = default;
GpuTimer::GpuTimer(GpuTimer&&) noexcept = default;
GpuTimer& GpuTimer::operator=(GpuTimer&&) noexcept = default;
GpuTimer::~GpuTimer() = default;

GpuTimer GpuTimer::create(uint32_t queries) {
    GpuTimer t;
    t.state_ = std::make_unique<State>();
    const uint32_t n = queries > 0 ? queries : 6;
    t.state_->all.resize(n);
    glCreateQueries(GL_TIME_ELAPSED, static_cast<GLsizei>(n), t.state_->all.data());
    t.state_->free_queries.assign(t.state_->all.rbegin(), t.state_->all.rend());
    return t;
}

void GpuTimer::begin() {
    State& s = *state_;
    assert(!s.active && "GpuTimer::begin twice without end");
    s.active = true;
    s.measuring = !s.free_queries.empty();
    if (!s.measuring) {
        ++s.skipped;
        ++s.frames;
        return;
    }
    const GLuint q = s.free_queries.back();
    s.free_queries.pop_back();
    glBeginQuery(GL_TIME_ELAPSED, q);
    s.pending.push_back({q, s.frames++, std::chrono::steady_clock::now()});
}

void GpuTimer::end() {
    State& s = *state_;
    assert(s.active && "GpuTimer::end without begin");
    s.active = false;
    if (s.measuring) glEndQuery(GL_TIME_ELAPSED);
}

std::vector<GpuTimer::Measurement> GpuTimer::poll() {
    State& s = *state_;
    std::vector<Measurement> out;
    const std::size_t open = s.active && s.measuring ? 1 : 0;  // the query of an unfinished pass stays
    while (s.pending.size() > open) {
        GLint available = 0;
        glGetQueryObjectiv(s.pending.front().query, GL_QUERY_RESULT_AVAILABLE, &available);
        if (available == 0) break;  // results arrive in order
        if (auto m = s.read(s.pending.front())) out.push_back(*m);
        s.pending.pop_front();
    }
    if (!out.empty()) s.latest = out.back();
    return out;
}

std::vector<GpuTimer::Measurement> GpuTimer::finish() {
    State& s = *state_;
    assert(!s.active && "GpuTimer::finish inside begin/end");
    std::vector<Measurement> out;
    while (!s.pending.empty()) {
        if (auto m = s.read(s.pending.front())) out.push_back(*m);  // GL_QUERY_RESULT waits
        s.pending.pop_front();
    }
    if (!out.empty()) s.latest = out.back();
    return out;
}

std::optional<GpuTimer::Measurement> GpuTimer::latest() const {
    return state_ ? state_->latest : std::nullopt;
}
uint64_t GpuTimer::skipped() const {
    return state_ ? state_->skipped : 0;
}
uint64_t GpuTimer::rejected() const {
    return state_ ? state_->rejected : 0;
}

void finish_gpu() {
    glFinish();
}

}  // namespace engine::gfx
