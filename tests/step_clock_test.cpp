// The step path's clock (exec/step_clock.hpp): its readings agree with CLOCK_MONOTONIC and the
// wall clock, never go back on a thread, and follow a step of the wall clock within 1 ms; with
// the TSC extrapolating and without.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "exec/step_clock.hpp"
#include "exec/wall_clock.hpp"

namespace dyad {
namespace {

int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A wall clock that a test steps: WallNowNs plus g_step_ns.
std::atomic<int64_t> g_step_ns{0};
int64_t SteppedWallNs() { return WallNowNs() + g_step_ns.load(); }

// Readings may lie outside the system clocks' readings around them by the extrapolation's error
// (ns) and a preempted measurement's (about 1 us at most, see ReadPair): far less than this. A
// TSC rate off by more than 1% is off by more at the end of a 1 ms span, a missed wall step by
// the step.
constexpr int64_t kToleranceNs = 10'000;

class StepClockTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    sources_ = {&SteadyNs, &SteppedWallNs, GetParam()};
    detail::SetStepClockSourcesForTest(&sources_);
    g_step_ns.store(0);
    // Past the TSC's calibration: the process's first reading starts it.
    (void)StepClockNow();
    std::this_thread::sleep_for(std::chrono::nanoseconds(2 * kCalibrationNs));
  }
  void TearDown() override {
    detail::SetStepClockSourcesForTest(nullptr);
    g_step_ns.store(0);
  }
  // Runs `body` on a thread of its own: a fresh anchor, made with this test's sources.
  template <class F>
  void OnFreshThread(F body) {
    std::thread t(body);
    t.join();
  }
  detail::StepClockSources sources_{};
};

TEST_P(StepClockTest, ReadingsAgreeWithTheSystemClocksAndNeverGoBack) {
  if (GetParam() && !detail::StepClockUsesTsc()) GTEST_SKIP() << "no invariant TSC as the kernel's clocksource here";
  OnFreshThread([] {
    int64_t previous = INT64_MIN;
    const int64_t end = SteadyNs() + 20 * kAnchorNs;  // some 20 anchors
    int64_t readings = 0;
    while (SteadyNs() < end || readings < 10000) {
      const int64_t steady_before = SteadyNs(), wall_before = WallNowNs();
      const ClockReading r = StepClockNow();
      const int64_t steady_after = SteadyNs(), wall_after = WallNowNs();
      ASSERT_GE(r.steady_ns, previous) << "went back on one thread, reading " << readings;
      ASSERT_GE(r.steady_ns, steady_before - kToleranceNs) << "reading " << readings;
      ASSERT_LE(r.steady_ns, steady_after + kToleranceNs) << "reading " << readings;
      ASSERT_GE(r.wall_ns, wall_before - kToleranceNs) << "reading " << readings;
      ASSERT_LE(r.wall_ns, wall_after + kToleranceNs) << "reading " << readings;
      previous = r.steady_ns;
      ++readings;
    }
  });
}

// Every reading taken kAnchorNs or more after the wall clock stepped shows the step, forward
// and back (an offset measured once and kept would not).
TEST_P(StepClockTest, AStepOfTheWallClockShowsWithinOneMillisecond) {
  if (GetParam() && !detail::StepClockUsesTsc()) GTEST_SKIP() << "no invariant TSC as the kernel's clocksource here";
  OnFreshThread([] {
    for (const int64_t step : {int64_t{3'600'000'000'000}, int64_t{-7'200'000'000'000}, int64_t{1'000'000}}) {
      for (int i = 0; i < 1000; ++i) (void)StepClockNow();  // an anchor made before the step
      const int64_t stepped_at = SteadyNs();
      g_step_ns.fetch_add(step);
      int64_t checked = 0;
      while (checked < 1000) {  // readings from 1 ms after the step on (some 2 ms of them)
        const int64_t steady_before = SteadyNs(), wall_before = SteppedWallNs();
        const ClockReading r = StepClockNow();
        const int64_t wall_after = SteppedWallNs();
        // 1 ms after the step, as the TSC's measured rate counts it: 1% of margin for its error.
        if (steady_before < stepped_at + kAnchorNs + kAnchorNs / 100) continue;
        ASSERT_GE(r.wall_ns, wall_before - kToleranceNs)
            << "a step of " << step << " ns not seen after " << steady_before - stepped_at << " ns";
        ASSERT_LE(r.wall_ns, wall_after + kToleranceNs)
            << "a step of " << step << " ns not seen after " << steady_before - stepped_at << " ns";
        ++checked;
      }
    }
  });
}

INSTANTIATE_TEST_SUITE_P(TscAndWithout, StepClockTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "Tsc" : "ClockGettime"; });

}  // namespace
}  // namespace dyad
