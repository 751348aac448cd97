#include "exec/step_clock.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <string>

#if defined(__x86_64__)
#include <cpuid.h>
#endif

#include "exec/wall_clock.hpp"

namespace dyad {
namespace detail {

constinit thread_local StepClockAnchor t_step_clock __attribute__((tls_model("initial-exec")));

namespace {

int64_t MonotonicNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

uint64_t ReadTsc() {
#if defined(__x86_64__)
  return __rdtsc();
#else
  return 0;
#endif
}

// The TSC counts at a constant rate whatever the CPU's frequency and sleep states (CPUID
// 80000007h EDX bit 8), and the kernel keeps time with it, which it does only once it has found
// the TSC synchronised across CPUs (else it falls back to another clocksource).
bool TscUsable() {
#if defined(__x86_64__)
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(0x80000007, &eax, &ebx, &ecx, &edx) == 0) return false;  // 0: no such leaf
  if ((edx & (1u << 8)) == 0) return false;
  std::ifstream in("/sys/devices/system/clocksource/clocksource0/current_clocksource");
  std::string source;
  return static_cast<bool>(in >> source) && source == "tsc";
#else
  return false;
#endif
}

// A TSC count and a steady reading of the same instant, the TSC read on both sides of the steady
// reading; tried again (up to three times, the closest pair kept) when the two TSC readings lie
// more than about a microsecond apart, so that a thread preempted in the middle does not offset a
// whole anchor's readings by its wait.
struct TscPair {
  uint64_t tsc = 0;
  int64_t steady_ns = 0;
};
constexpr uint64_t kCloseTicks = 3000;  // 1 us at 3 GHz (TSCs run at 1-4 GHz)
TscPair ReadPair(int64_t (*steady_ns)()) {
  TscPair best;
  uint64_t best_gap = UINT64_MAX;
  for (int i = 0; i < 3 && best_gap > kCloseTicks; ++i) {
    const uint64_t before = ReadTsc();
    const int64_t steady = steady_ns();
    const uint64_t gap = ReadTsc() - before;
    if (gap < best_gap) {
      best_gap = gap;
      best = {before + gap / 2, steady};
    }
  }
  return best;
}

// Wall minus steady: the wall read between two steady readings (their midpoint), tried again in
// the same way when they lie more than a microsecond apart.
int64_t WallMinusSteady(const StepClockSources& src) {
  int64_t best = 0, best_gap = INT64_MAX;
  for (int i = 0; i < 3 && best_gap > 1000; ++i) {
    const int64_t before = src.steady_ns();
    const int64_t wall = src.wall_ns();
    const int64_t gap = src.steady_ns() - before;
    if (gap < best_gap) {
      best_gap = gap;
      best = wall - (before + gap / 2);
    }
  }
  return best;
}

// The process's first reading: the TSC's rate is measured from here.
struct Origin {
  bool tsc_usable = false;
  TscPair at;
};

const Origin& TheOrigin() {
  static const Origin origin = [] {
    Origin o;
    o.tsc_usable = TscUsable();
    o.at = ReadPair(&MonotonicNs);
    return o;
  }();
  return origin;
}

const StepClockSources kDefaultSources{&MonotonicNs, &WallNowNs, true};
std::atomic<const StepClockSources*> g_sources{&kDefaultSources};

// ns per tick in 32.32 fixed point, measured since the origin; 0 until kCalibrationNs have passed.
uint64_t TscMult(const Origin& o, const TscPair& now) {
  const int64_t elapsed = now.steady_ns - o.at.steady_ns;
  if (elapsed < kCalibrationNs || now.tsc <= o.at.tsc) return 0;
  return static_cast<uint64_t>((static_cast<unsigned __int128>(elapsed) << 32) / (now.tsc - o.at.tsc));
}

}  // namespace

void SetStepClockSourcesForTest(const StepClockSources* sources) {
  g_sources.store(sources != nullptr ? sources : &kDefaultSources, std::memory_order_release);
}

bool StepClockUsesTsc() { return TheOrigin().tsc_usable && g_sources.load(std::memory_order_acquire)->use_tsc; }

// Extrapolating: a new anchor when its span has run out. Else a steady reading, and the wall
// offset measured again when it is kAnchorNs old.
ClockReading StepClockRenew() {
  StepClockAnchor& a = t_step_clock;
  const StepClockSources& src = *g_sources.load(std::memory_order_acquire);
  const bool tsc = TheOrigin().tsc_usable && src.use_tsc;
  const TscPair now = tsc ? ReadPair(src.steady_ns) : TscPair{0, src.steady_ns()};
  int64_t steady = now.steady_ns;
  if (!a.has_offset || steady - a.offset_steady_ns >= kAnchorNs || a.span > 0) {
    a.wall_minus_steady = WallMinusSteady(src);
    a.offset_steady_ns = steady;
    a.has_offset = true;
    a.mult = tsc ? TscMult(TheOrigin(), now) : 0;
    a.tsc = now.tsc;
    a.steady_ns = steady;
    a.span = a.mult > 0 ? (static_cast<uint64_t>(kAnchorNs) << 32) / a.mult : 0;
  }
  if (steady < a.last_ns) steady = a.last_ns;
  a.last_ns = steady;
  return {steady, steady + a.wall_minus_steady};
}

}  // namespace detail
}  // namespace dyad
