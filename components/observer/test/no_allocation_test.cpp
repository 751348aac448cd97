// The observer's Step promises no heap allocation once configured (10 Hz hot path). This binary
// replaces the global operator new to count allocations while Step runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <new>

#include "fake_context.hpp"
#include "observer_component.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace dyad::observer {
namespace {

class DiscardingWriter final : public detail::WriterEndpoint {
 public:
  Status Write(const void*) override { return Status::OK(); }
};

TEST(NoAllocation, ObserverStepAllocatesNothing) {
  ClassifierSpec s;  // the study's shape
  ObserverFile f;
  f.classifier = Classifier::Create(s, 1).value();
  const std::string path =
      (std::filesystem::temp_directory_path() / ("dyad_observer_noalloc_" + std::to_string(getpid()) + ".dobs")).string();
  ASSERT_TRUE(SaveObserver(f, path).ok());
  testing::FakeContext ctx(&Observer::Describe, {{"model", path}});
  auto& human = ctx.Feed<msg::HumanInput>("human");
  auto& robot = ctx.Feed<msg::Intention>("robot");
  DiscardingWriter sink;
  testing::FakeClock clock;
  Observer o;
  ASSERT_TRUE(o.Configure(ctx).ok());
  // Bind after Configure: the fake context's outputs are reachable only through ctx.output().
  ctx.output<msg::IntentionLabel>("labels").Bind("labels", "labels", "test", &sink, &clock);
  long during_steps = 0;
  for (int k = 0; k < 60; ++k) {
    msg::HumanInput h;
    h.x(k % 17);
    h.y(-k % 11);
    h.engaged((k / 20) % 2 == 0);  // engaged, released, engaged again
    msg::Intention r;
    r.x(k % 13);
    r.y(k % 7);
    human.queue.push_back(h);
    robot.queue.push_back(r);
    ctx.PollInputs();
    const long before = g_allocations.load();
    ASSERT_TRUE(o.Step({.now_ns = 0, .index = static_cast<uint64_t>(k)}).ok());
    if (k >= 10) during_steps += g_allocations.load() - before;  // after every buffer has been used once
  }
  EXPECT_EQ(during_steps, 0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace dyad::observer
