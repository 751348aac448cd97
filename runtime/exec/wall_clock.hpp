// The runtime's wall clock (internal): what stamps samples in wall-clock runs, what the start
// barrier agrees on and what clock sync compares across processes.
//
// Test only: DYAD_TEST_CLOCK_OFFSET_MS (a number, may be negative) shifts this process's wall
// clock, to rehearse hosts whose clocks disagree (tests/multihost_test.sh). It is read once and
// said on stderr, so it cannot go unnoticed in a real run.
#pragma once

#include <cstdint>

namespace dyad {

int64_t WallNowNs();

}  // namespace dyad
