// The counting replacement of the global operator new/delete (see allocation_counter.hpp). In a
// translation unit of its own, so no test inlines malloc/free pairs into its code (GCC 12 then
// warns -Wmismatched-new-delete about correct pairs).
#include "dyad/testing/allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
thread_local long t_allocations = 0;  // trivial: no initialisation that could allocate
}  // namespace

namespace dyad::testing {
long AllocationCount() { return g_allocations.load(std::memory_order_relaxed); }
long AllocationCountOnThisThread() { return t_allocations; }
}  // namespace dyad::testing

// Every form malloc-backed, so every delete matches whichever new made the block.
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  ++t_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  ++t_allocations;
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
