// The schedule: named systems run in the order they were added, each timed per frame (last and mean wall
// time) for a stats panel, and each given the registry tick of its own previous run for change tracking.
#pragma once

#include <engine/ecs/config.hpp>
#include <engine/ecs/registry.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace engine::ecs {

/// What a system gets besides the registry, for the current frame.
struct FrameContext {
    std::uint64_t frame_index = 0;    ///< 0 on the first run() of the schedule
    double dt_s = 0.0;                ///< the dt passed to run()
    double time_s = 0.0;              ///< sum of dt over all run() calls so far, including this one
    std::uint64_t last_run_tick = 0;  ///< registry.tick() when this system last finished (0 before its first
                                      ///< run): pass it to registry.changed<T>() to see what changed since
    void* user = nullptr;             ///< the game's own frame data, passed through run() untouched
};

/// Wall time of one system, in milliseconds.
struct SystemStats {
    std::string name;        ///< the name given to Schedule::add
    double last_ms = 0.0;    ///< last frame it ran
    double mean_ms = 0.0;    ///< mean over all frames it ran
    double max_ms = 0.0;     ///< longest frame it ran
    std::uint64_t runs = 0;  ///< frames it ran
};

/// Named systems run in order once per frame (see the file comment).
class Schedule {
public:
    /// A system: reads and writes the registry, gets the frame's FrameContext.
    using SystemFn = std::function<void(Registry&, const FrameContext&)>;

    /// Appends a system; systems run in the order they were added. Asserts the name is non-empty and new.
    Schedule& add(std::string name, SystemFn fn) {
        ENGINE_ECS_ASSERT(!name.empty(), "schedule: a system needs a name");
        ENGINE_ECS_ASSERT(find(name) == nullptr, "schedule: a system with this name was already added");
        ENGINE_ECS_ASSERT(static_cast<bool>(fn), "schedule: empty system function");
        stats_.push_back(SystemStats{.name = std::move(name)});
        systems_.push_back(System{std::move(fn), 0});
        return *this;
    }

    /// Runs every system once, in order, on `registry`, timing each. A schedule is meant to drive one
    /// registry: the per-system last_run_tick values are ticks of that registry.
    void run(Registry& registry, double dt_s, void* user = nullptr) {
        using Clock = std::chrono::steady_clock;
        time_s_ += dt_s;
        const Clock::time_point frame_start = Clock::now();
        for (std::size_t i = 0; i < systems_.size(); ++i) {
            const FrameContext ctx{.frame_index = frame_index_,
                                   .dt_s = dt_s,
                                   .time_s = time_s_,
                                   .last_run_tick = systems_[i].last_run_tick,
                                   .user = user};
            const Clock::time_point start = Clock::now();
            systems_[i].fn(registry, ctx);
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
            systems_[i].last_run_tick = registry.tick();
            SystemStats& s = stats_[i];
            s.last_ms = ms;
            s.runs += 1;
            s.mean_ms += (ms - s.mean_ms) / static_cast<double>(s.runs);
            s.max_ms = s.runs == 1 ? ms : std::max(s.max_ms, ms);
        }
        last_frame_ms_ = std::chrono::duration<double, std::milli>(Clock::now() - frame_start).count();
        ++frame_index_;
    }

    /// Timing of the system called `name`, or nullptr if there is none.
    [[nodiscard]] const SystemStats* find(std::string_view name) const noexcept {
        for (const SystemStats& s : stats_)
            if (s.name == name) return &s;
        return nullptr;
    }
    /// Timing of all systems, in run order.
    [[nodiscard]] std::span<const SystemStats> stats() const noexcept { return stats_; }
    /// Number of systems added.
    [[nodiscard]] std::size_t size() const noexcept { return systems_.size(); }
    /// Number of completed run() calls.
    [[nodiscard]] std::uint64_t frames() const noexcept { return frame_index_; }
    /// Wall time of the whole last run(), in milliseconds (systems plus the schedule's own overhead).
    [[nodiscard]] double last_frame_ms() const noexcept { return last_frame_ms_; }

private:
    struct System {
        SystemFn fn;
        std::uint64_t last_run_tick;
    };
    std::vector<System> systems_;
    std::vector<SystemStats> stats_;
    std::uint64_t frame_index_ = 0;
    double time_s_ = 0.0;
    double last_frame_ms_ = 0.0;
};

}  // namespace engine::ecs
