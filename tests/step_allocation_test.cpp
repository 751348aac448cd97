// The runtime's step path allocates nothing once warm (docs/runtime.md, "Benchmark: a hop"): a
// periodic component publishing to a triggered one, with a live parameter (its check registered,
// LiveParams at every step boundary) and input health read at every poll, on the wall clock
// (the triggered step inside the publisher's Publish(), as in bench_pingpong) and the stepped
// one. The samples carry a 256-byte payload and a header naming a writer whose name is past the
// standard library's short-string size: an input that gave its storage away at every poll
// allocated for both, each sample. The transport here moves samples by copy assignment into
// storage it keeps (Fast DDS's own allocations are not the runtime's), and the count is the step
// thread's (dyad/testing/allocation_counter.hpp), so other threads cannot disturb it.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include <dyad/msg/types.hpp>

#include "dyad/testing/allocation_counter.hpp"
#include "exec/executor.hpp"

namespace dyad {
namespace {

// Allocations on the step thread between consecutive steps of the source (its step, the
// triggered sink's inside its Publish(), and the runtime's work around both).
std::vector<long>* g_between = nullptr;
constexpr int kWarmSteps = 20, kSteps = 120;

class Source final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Param("gain", 1.0).Live();
    spec.Output<msg::PingPong>("out");
  }
  Status Configure(Context& ctx) override {
    ctx.CheckLiveParam("gain", [](const ParamValue&) { return Status::OK(); });
    ctx_ = &ctx;
    out_ = &ctx.output<msg::PingPong>("out");
    sample_.payload().assign(256, 7);
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    const long now = testing::AllocationCountOnThisThread();
    if (info.index > kWarmSteps) g_between->push_back(now - last_);  // reserved: no allocation
    last_ = now;
    if (info.index == kSteps) {
      ctx_->RequestStop("done");
      return Status::OK();
    }
    sample_.id(info.index);
    sample_.t0_ns(static_cast<int64_t>(ctx_->params().Double("gain")));
    return out_->Publish(sample_);
  }

 private:
  Context* ctx_ = nullptr;
  Output<msg::PingPong>* out_ = nullptr;
  msg::PingPong sample_;
  long last_ = 0;
};

class Sink final : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Param("gain", 1.0).Live();
    spec.Input<msg::PingPong>("in");
  }
  Status Configure(Context& ctx) override {
    ctx.CheckLiveParam("gain", [](const ParamValue&) { return Status::OK(); });
    ctx_ = &ctx;
    in_ = &ctx.input<msg::PingPong>("in");
    return Status::OK();
  }
  Status Step(const StepInfo&) override {
    for (const auto& s : in_->received()) sum_ += s.payload().size() + s.header().source().size();
    if (in_->latest() == nullptr || in_->writers_alive() == 0) return Status::Internal("no sample");
    sum_ += static_cast<uint64_t>(ctx_->params().Double("gain"));
    return Status::OK();
  }

 private:
  Context* ctx_ = nullptr;
  Input<msg::PingPong>* in_ = nullptr;
  uint64_t sum_ = 0;
};

// A transport whose endpoints allocate nothing once warm: a writer copy-assigns its sample into
// each reader's slot of the topic (storage reused) and calls the reader's on_data, inside
// Write() as Fast DDS does within a process. Samples of the runtime's own topics are dropped.
class QuietTransport final : public Transport {
 public:
  StatusOr<TypedReader*> CreateReader(const std::string& topic, const TypeInfo&, const TopicQos&,
                                      std::function<void()> on_data) override {
    readers_.push_back(std::make_unique<Reader>(topic == "samples", std::move(on_data)));
    return readers_.back().get();
  }
  StatusOr<TypedWriter*> CreateWriter(const std::string& topic, const TypeInfo&, const TopicQos&) override {
    writers_.push_back(std::make_unique<Writer>(topic == "samples" ? this : nullptr));
    return writers_.back().get();
  }
  StatusOr<SerializedSubscription*> CreateSerializedReader(const std::string&, const TypeInfo&, const TopicQos&, const Clock*,
                                                           SerializedCallback) override {
    return Status::Unimplemented("not in this test");
  }
  StatusOr<SerializedWriter*> CreateSerializedWriter(const std::string&, const TypeInfo&, const TopicQos&,
                                                     const Clock*) override {
    return Status::Unimplemented("not in this test");
  }

 private:
  class Reader final : public TypedReader {
   public:
    Reader(bool samples, std::function<void()> on_data) : samples(samples), on_data(std::move(on_data)) {}
    bool TakeNext(void* sample) override {
      if (!full) return false;
      *static_cast<msg::PingPong*>(sample) = slot;
      full = false;
      return true;
    }
    uint64_t Unread() const override { return full ? 1 : 0; }
    int AliveWriters() const override { return 1; }
    const bool samples;
    const std::function<void()> on_data;
    msg::PingPong slot;
    bool full = false;
  };
  class Writer final : public TypedWriter {
   public:
    explicit Writer(QuietTransport* to) : to_(to) {}
    Status Write(const void* sample) override {
      if (to_ == nullptr) return Status::OK();
      for (auto& r : to_->readers_) {
        if (!r->samples) continue;
        r->slot = *static_cast<const msg::PingPong*>(sample);
        r->full = true;
        if (r->on_data) r->on_data();
      }
      return Status::OK();
    }
    int matched() const override { return 1; }
    bool AwaitAcknowledged(double) override { return true; }

   private:
    QuietTransport* to_;
  };
  std::vector<std::unique_ptr<Reader>> readers_;
  std::vector<std::unique_ptr<Writer>> writers_;
};

void Register(PluginRegistry& r) {
  r.Add<Source>("alloc_source");
  r.Add<Sink>("alloc_sink");
}

class StepAllocation : public ::testing::TestWithParam<const char*> {};

TEST_P(StepAllocation, NoStepAllocatesOnceWarm) {
  Catalog catalog;
  ASSERT_TRUE(catalog.Register("step_allocation_test", &Register).ok());
  // The writer's name is longer than a short string (15 characters in libstdc++).
  const std::string yaml = std::string("graph: alloc\nclock: ") + GetParam() +
                           "\ncomponents:\n"
                           "  a_source_with_a_long_name: {type: alloc_source, rate_hz: 500, outputs: {out: samples}}\n"
                           "  sink: {type: alloc_sink, trigger: in, inputs: {in: samples}}\n"
                           "topics:\n"
                           "  samples: {reliability: reliable, depth: 1, deadline_ms: 100, liveliness_ms: 500}\n";
  std::vector<Diagnostic> diags;
  Graph graph = ParseGraph(yaml, "alloc.yaml", {}, &diags);
  ResolvedGraph resolved = ValidateGraph(graph, catalog, &diags);
  for (const auto& d : diags) ADD_FAILURE() << d.ToString();
  ASSERT_TRUE(diags.empty());
  std::vector<long> between;
  between.reserve(kSteps);
  g_between = &between;
  Executor::Options o;
  o.process = "main";
  // Stepped: no stats between the steps on the step thread (their messages allocate).
  if (std::string(GetParam()) == "stepped") o.stats_period_s = 0;
  o.transport = [](const std::string&, bool) -> StatusOr<std::unique_ptr<Transport>> {
    return std::unique_ptr<Transport>(new QuietTransport());
  };
  auto ex = std::make_unique<Executor>(graph, resolved, &catalog, o);
  ASSERT_TRUE(ex->Run().ok());
  ex.reset();
  g_between = nullptr;
  ASSERT_EQ(between.size(), static_cast<size_t>(kSteps - kWarmSteps));
  long total = 0;
  for (long n : between) total += n;
  EXPECT_EQ(total, 0) << "allocations in " << between.size() << " steps of each component";
}

INSTANTIATE_TEST_SUITE_P(Clocks, StepAllocation, ::testing::Values("wall", "stepped"));

}  // namespace
}  // namespace dyad
