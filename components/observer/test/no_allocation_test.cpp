// The observer's Step promises no heap allocation once configured (10 Hz hot path). This binary
// replaces the global operator new to count allocations while Step runs.
#include <gtest/gtest.h>

#include "dyad/testing/allocation_counter.hpp"
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "dyad/testing/fake_context.hpp"
#include "observer_component.hpp"


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
    const long before = dyad::testing::AllocationCount();
    ASSERT_TRUE(o.Step({.now_ns = 0, .index = static_cast<uint64_t>(k)}).ok());
    if (k >= 10) during_steps += dyad::testing::AllocationCount() - before;  // after every buffer has been used once
  }
  EXPECT_EQ(during_steps, 0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace dyad::observer
