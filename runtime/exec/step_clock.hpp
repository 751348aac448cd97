// The step path's clock (internal): the steady and the wall time of one instant from one cheap
// reading, for what the executor reads on every step and every Publish() (the step timer's start
// and end, StepInfo::now_ns, a wall-clock run's sample stamps).
//
// Why: std::chrono's clocks cost a vDSO clock_gettime each (17 ns on the development VM: a
// serialising rdtsc, a sequence lock, a conversion) and bench_pingpong's round trip read them 8
// times in dyad's runtime, 6 more than bare Fast DDS (#42 item 4). Here:
// - steady time is the TSC (__rdtsc, 7.6 ns there) extrapolated from a per-thread anchor (a TSC
//   count and CLOCK_MONOTONIC read together), at a rate measured against CLOCK_MONOTONIC since
//   the process's first reading. Used only where the TSC is invariant (CPUID) and is the kernel's
//   clocksource (so it is synchronised across CPUs); elsewhere, and for the first
//   kCalibrationNs, each reading reads CLOCK_MONOTONIC instead.
// - wall time is that steady time plus wall minus steady as measured at the anchor (one
//   reading instead of two). NTP slews CLOCK_MONOTONIC and CLOCK_REALTIME alike, so only a step of
//   the wall clock (settimeofday, an NTP step) changes the difference: it is measured again on a
//   thread's first reading at least kAnchorNs (1 ms) of steady time after the last measurement.
//   Bound: a reading reflects every step of the wall clock made at least 1 ms before it (with the
//   TSC, 1 ms as its measured rate counts it: a few ppm off).
// - Steady readings never go back on one thread (a new anchor's CLOCK_MONOTONIC may lie a few ns
//   behind the extrapolation: the rate is an average, and NTP may slew the clock meanwhile; such
//   a reading repeats the previous one). Between threads they agree to that extrapolation error
//   (a few ns; at most the slew rate, 500 ppm, times 1 ms).
// The wall time includes DYAD_TEST_CLOCK_OFFSET_MS (it comes from WallNowNs, wall_clock.hpp).
// Thread-safe: each thread keeps its own anchor (initial-exec TLS: no call to reach it).
#pragma once

#include <cstdint>

#if defined(__x86_64__)
#include <x86intrin.h>
#endif

namespace dyad {

struct ClockReading {
  int64_t steady_ns = 0;  // std::chrono::steady_clock's epoch (CLOCK_MONOTONIC)
  int64_t wall_ns = 0;    // ns since the Unix epoch (WallNowNs's, DYAD_TEST_CLOCK_OFFSET_MS included)
};

inline constexpr int64_t kAnchorNs = 1'000'000;        // a thread's wall offset is at most this old
inline constexpr int64_t kCalibrationNs = 10'000'000;  // the TSC's rate is measured over at least this

namespace detail {

// One thread's anchor. span 0: no extrapolation (before calibration, or without a usable TSC).
struct StepClockAnchor {
  uint64_t tsc = 0;               // TSC count at the anchor
  uint64_t span = 0;              // ticks after the anchor within which readings extrapolate
  uint64_t mult = 0;              // ns per tick, 32.32 fixed point
  int64_t steady_ns = 0;          // CLOCK_MONOTONIC at the anchor
  int64_t wall_minus_steady = 0;  // measured at offset_steady_ns
  int64_t offset_steady_ns = 0;   // when wall_minus_steady was measured
  bool has_offset = false;
  int64_t last_ns = INT64_MIN;  // the last steady time returned on this thread
};
// constinit: no dynamic initialisation, so no TLS wrapper call on each access.
extern thread_local constinit StepClockAnchor t_step_clock __attribute__((tls_model("initial-exec")));

// A new anchor (or, without extrapolation, a reading of CLOCK_MONOTONIC and the offset if due).
ClockReading StepClockRenew();

// Where readings come from, for tests: a wall clock that steps, the TSC switched off. Applies to
// anchors made afterwards (a fresh thread's); the default is CLOCK_MONOTONIC, WallNowNs, the TSC
// where usable.
struct StepClockSources {
  int64_t (*steady_ns)();
  int64_t (*wall_ns)();
  bool use_tsc;
};
void SetStepClockSourcesForTest(const StepClockSources* sources);  // nullptr: the defaults
// Whether the TSC extrapolates readings in this process (invariant, the kernel's clocksource).
bool StepClockUsesTsc();

}  // namespace detail

inline ClockReading StepClockNow() {
#if defined(__x86_64__)
  detail::StepClockAnchor& a = detail::t_step_clock;
  const uint64_t ticks = __rdtsc() - a.tsc;  // wraps to a huge count if the TSC looks back: renewed
  if (ticks < a.span) {
    int64_t steady = a.steady_ns + static_cast<int64_t>((ticks * a.mult) >> 32);
    if (steady < a.last_ns) steady = a.last_ns;
    a.last_ns = steady;
    return {steady, steady + a.wall_minus_steady};
  }
#endif
  return detail::StepClockRenew();
}

}  // namespace dyad
