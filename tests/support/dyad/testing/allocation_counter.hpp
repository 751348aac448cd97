// dyad/testing/allocation_counter.hpp: counts heap allocations, for tests that check a hot path
// allocates nothing (test code only).
//
// Link the target `dyad_allocation_counter` (an object library): it replaces the global
// operator new/delete of the test binary with counting versions. Then
//   EXPECT_EQ(dyad::testing::CountAllocations([&] { component.Step(info); }), 0);
#pragma once

#include <utility>

namespace dyad::testing {

// Allocations made by this process so far (all threads).
long AllocationCount();
// Allocations made by the calling thread so far: a hot path's own, while other threads (a
// middleware's, a logger's) allocate as they please.
long AllocationCountOnThisThread();

// Allocations made while f() runs.
template <typename F>
long CountAllocations(F&& f) {
  const long before = AllocationCount();
  std::forward<F>(f)();
  return AllocationCount() - before;
}

}  // namespace dyad::testing
