// dyad/testing/dds_domain.hpp: the DDS domain a test process uses for the graphs it runs (test
// code only), so that parallel ctest processes with wall-clock graphs don't hear each other.
// (Stepped graphs are hermetic anyway: their participant ignores other processes.)
#pragma once

#include <unistd.h>

namespace dyad::testing {

// 1..200, from the process id: distinct for concurrently running test processes unless their
// ids collide modulo 200.
inline int DomainForThisProcess() { return 1 + static_cast<int>(getpid() % 200); }

}  // namespace dyad::testing
