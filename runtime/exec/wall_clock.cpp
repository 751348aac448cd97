#include "exec/wall_clock.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace dyad {
namespace {

int64_t TestOffsetNs() {
  const char* text = std::getenv("DYAD_TEST_CLOCK_OFFSET_MS");
  if (text == nullptr || *text == '\0') return 0;
  char* end = nullptr;
  const double ms = std::strtod(text, &end);
  if (*end != '\0' || !std::isfinite(ms)) {
    std::fprintf(stderr, "dyad: DYAD_TEST_CLOCK_OFFSET_MS='%s' is not a number: ignored\n", text);
    return 0;
  }
  std::fprintf(stderr, "dyad: test only: this process's clock is shifted by %g ms (DYAD_TEST_CLOCK_OFFSET_MS)\n", ms);
  return static_cast<int64_t>(std::llround(ms * 1e6));
}

}  // namespace

int64_t WallNowNs() {
  static const int64_t offset = TestOffsetNs();
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count() +
         offset;
}

}  // namespace dyad
