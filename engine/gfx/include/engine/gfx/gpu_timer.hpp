// GPU time of one pass (a stretch of GL commands), measured with GL_TIME_ELAPSED queries and read back a few
// frames later without stalling: begin()/end() around the pass each frame, poll() once a frame collects the
// queries whose results are available. With every query still pending, begin() skips that frame's measurement
// (counted in skipped()) rather than wait.
//
//   engine::gfx::GpuTimer timer = engine::gfx::GpuTimer::create();
//   timer.begin(); draw(); timer.end();
//   for (const auto& m : timer.poll()) log(m.frame, m.ms);   // frames measured earlier, now finished
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace engine::gfx {

class GpuTimer {
public:
    struct Measurement {
        uint64_t frame = 0;  ///< index of the begin() call (0, 1, 2, ...) the result belongs to
        double ms = 0.0;     ///< GPU time between begin() and end()
    };

    /// `queries` in flight at most (0 -> 6). Needs a current GL context with timer queries (GL 3.3+).
    static GpuTimer create(uint32_t queries = 0);

    GpuTimer();
    GpuTimer(GpuTimer&&) noexcept;
    GpuTimer& operator=(GpuTimer&&) noexcept;
    ~GpuTimer();

    /// Starts a measurement (GL_TIME_ELAPSED queries do not nest: one timer's pass at a time).
    void begin();
    void end();
    /// Finished measurements since the last poll(), oldest first. Never waits.
    std::vector<Measurement> poll();
    /// Waits for every pending measurement and returns them (end of a run, tests).
    std::vector<Measurement> finish();
    /// The newest measurement any poll()/finish() returned.
    [[nodiscard]] std::optional<Measurement> latest() const;
    /// begin() calls skipped because every query was still pending.
    [[nodiscard]] uint64_t skipped() const;
    /// Results dropped as impossible (longer than the wall time from begin() to read-back).
    [[nodiscard]] uint64_t rejected() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

/// glFinish: blocks until the GPU has done everything issued so far (benchmarks timing a frame end to end).
void finish_gpu();

}  // namespace engine::gfx
