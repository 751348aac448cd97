// The executor on an in-memory transport (memory_transport.hpp), as rclcpp tests its executors:
// trigger delivery, lifecycle order and threads, the cap on triggered cycles, a failure in each
// phase (its Status code kept), teardown order, and timing charged to the component that spent it.
#include "exec/executor.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <regex>
#include <thread>

#include <dyad/decode_sample.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/on_demand_subscription.hpp>

#include "exec/wall_clock.hpp"
#include "memory_transport.hpp"

namespace dyad {
namespace {

// What the test components did, in order, from every thread.
struct EventLog {
  std::mutex mutex;
  std::vector<std::string> events;
  std::vector<std::thread::id> lifecycle_threads;  // of configure/activate/deactivate/shutdown
  void Add(const std::string& e) {
    std::lock_guard<std::mutex> lock(mutex);
    events.push_back(e);
  }
  void AddLifecycle(const std::string& e) {
    std::lock_guard<std::mutex> lock(mutex);
    events.push_back(e);
    lifecycle_threads.push_back(std::this_thread::get_id());
  }
  std::vector<std::string> Matching(const std::string& needle) {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::string> out;
    for (const auto& e : events)
      if (e.find(needle) != std::string::npos) out.push_back(e);
    return out;
  }
};
EventLog* g_log = nullptr;

Status Fail(const std::string& code, const std::string& what) {
  if (code == "io") return Status::IOError(what);
  if (code == "dataloss") return Status::DataLoss(what);
  return Status::InvalidArgument(what);
}

// A test component: logs its lifecycle, fails in the phase `fail` names (with code `code`),
// publishes `out` = step index, records what `in` received, sleeps `sleep_ms` per step.
class Probe : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Param("fail", "").OneOf({"", "configure", "activate", "step", "deactivate"});
    spec.Param("code", "invalid");
    spec.Param("fail_step", 2);
    spec.Param("sleep_ms", 0.0);
    spec.Param("activate_ms", 0.0);  // Activate takes this long (a web component's wait for its page)
    spec.Param("deactivate_ms", 0.0);  // Deactivate takes this long (a recorder writing its summary)
    spec.Param("tap", "");  // a topic to subscribe serialized (sleeping sleep_ms per callback)
    // tap on demand: started at step tap_start, stopped at step tap_stop (-1: never)
    spec.Param("tap_start", -1);
    spec.Param("tap_stop", -1);
    spec.Input<msg::Counter>("in").Optional();
    spec.Output<msg::Counter>("out");
  }
  ~Probe() override {
    if (g_log) g_log->Add(name_ + " destroyed");
  }
  Status Configure(Context& ctx) override {
    name_ = ctx.name();
    g_log->AddLifecycle(name_ + " configure");
    fail_ = ctx.params().String("fail");
    code_ = ctx.params().String("code");
    fail_step_ = static_cast<uint64_t>(ctx.params().Int("fail_step"));
    sleep_ = std::chrono::duration<double, std::milli>(ctx.params().Double("sleep_ms"));
    activate_ = std::chrono::duration<double, std::milli>(ctx.params().Double("activate_ms"));
    deactivate_ = std::chrono::duration<double, std::milli>(ctx.params().Double("deactivate_ms"));
    in_ = &ctx.input<msg::Counter>("in");
    out_ = &ctx.output<msg::Counter>("out");
    tap_start_ = ctx.params().Int("tap_start");
    tap_stop_ = ctx.params().Int("tap_stop");
    if (const std::string tap = ctx.params().String("tap"); !tap.empty()) {
      SerializedCallback cb = [this](const SerializedSample&) {
        std::this_thread::sleep_for(sleep_);
        ++tapped_;
      };
      if (tap_start_ >= 0) {
        auto sub = SubscribeSerializedOnDemand(ctx, tap, std::move(cb));
        if (!sub.ok()) return sub.status();
        on_demand_ = *sub;
      } else if (Status s = ctx.SubscribeSerialized(tap, std::move(cb)); !s.ok()) {
        return s;
      }
    }
    if (fail_ == "configure") return Fail(code_, "boom");
    return Status::OK();
  }
  Status Activate() override {
    g_log->AddLifecycle(name_ + " activate");
    std::this_thread::sleep_for(activate_);
    return fail_ == "activate" ? Fail(code_, "boom") : Status::OK();
  }
  Status Step(const StepInfo& info) override {
    if (busy_.exchange(true)) g_log->Add(name_ + " OVERLAPPING STEP");
    for (const auto& s : in_->received()) g_log->Add(name_ + " got " + std::to_string(s.value()));
    g_log->Add(name_ + " step " + std::to_string(info.index));
    if (sleep_.count() > 0 && tapped_ == 0) std::this_thread::sleep_for(sleep_);
    if (on_demand_ != nullptr && static_cast<int64_t>(info.index) == tap_start_)
      if (Status st = on_demand_->Start(); !st.ok()) return st;
    if (on_demand_ != nullptr && static_cast<int64_t>(info.index) == tap_stop_) on_demand_->Stop();
    msg::Counter c;
    c.value(static_cast<int64_t>(info.index));
    Status s = out_->Publish(c);
    busy_.store(false);
    if (fail_ == "step" && info.index == fail_step_) return Fail(code_, "boom");
    return s;
  }
  Status Deactivate() override {
    g_log->AddLifecycle(name_ + " deactivate (tapped " + std::to_string(tapped_) + ")");
    std::this_thread::sleep_for(deactivate_);
    return fail_ == "deactivate" ? Fail(code_, "boom") : Status::OK();
  }
  void Shutdown() override { g_log->AddLifecycle(name_ + " shutdown"); }

 private:
  std::string name_, fail_, code_;
  uint64_t fail_step_ = 0;
  std::chrono::duration<double, std::milli> sleep_{0}, activate_{0}, deactivate_{0};
  Input<msg::Counter>* in_ = nullptr;
  Output<msg::Counter>* out_ = nullptr;
  std::atomic<bool> busy_{false};
  std::atomic<int> tapped_{0};
  int64_t tap_start_ = -1, tap_stop_ = -1;
  OnDemandSubscription* on_demand_ = nullptr;  // owned by the runtime
};

// A component with a live param whose preparation takes `prepare_ms` (1.5 s for 9, refusing 13)
// and a plain live param: logs each step's values, whether a preparation was running meanwhile,
// and each commit.
class Slow : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Param("level", 0).Live();
    spec.Param("other", 0).Live();
    spec.Param("prepare_ms", 300.0);
  }
  Status Configure(Context& ctx) override {
    ctx_ = &ctx;
    const auto prepare = std::chrono::duration<double, std::milli>(ctx.params().Double("prepare_ms"));
    ctx.PrepareLiveParam(
        "level",
        [this, prepare](const ParamValue& v) {
          preparing_.store(true);
          const int64_t other = ctx_->params().Int("other");  // held still while this runs
          std::this_thread::sleep_for(std::get<int64_t>(v) == 9 ? std::chrono::duration<double, std::milli>(1500) : prepare);
          preparing_.store(false);
          if (ctx_->params().Int("other") != other) return Status::Internal("other changed during the preparation");
          return std::get<int64_t>(v) == 13 ? Status::InvalidArgument("unlucky") : Status::OK();
        },
        [](const ParamValue& v) { g_log->Add("slow commit " + std::to_string(std::get<int64_t>(v))); });
    return Status::OK();
  }
  Status Step(const StepInfo& info) override {
    g_log->Add("slow step " + std::to_string(info.index) + " level " + std::to_string(ctx_->params().Int("level")) + " other " +
               std::to_string(ctx_->params().Int("other")) + (preparing_.load() ? " while preparing" : ""));
    return Status::OK();
  }

 private:
  Context* ctx_ = nullptr;
  std::atomic<bool> preparing_{false};
};

// Asks for live changes of `slow` at its steps: level 5 then other 7 at step 2, level 13 at
// step 4, level 9 at step `last` (prepared for longer than the run lasts); logs the answers.
class Asker : public Component {
 public:
  static void Describe(ComponentSpec& spec) {
    spec.Param("last", 1000);
    spec.Output<msg::ParamChange>("requests");
  }
  Status Configure(Context& ctx) override {
    graph_ = ctx.graph_name();
    last_ = static_cast<uint64_t>(ctx.params().Int("last"));
    out_ = &ctx.output<msg::ParamChange>("requests");
    // Every answer, also those given after the last step (until just before Deactivate).
    return ctx.SubscribeSerialized("dyad/params", [](const SerializedSample& sample) {
      msg::ParamChange a;
      if (!DecodeSample(sample.cdr, &a).ok()) return g_log->Add("answer undecodable");
      g_log->Add("answer " + a.op() + " " + a.param_name() + " " + a.value() + (a.reason().empty() ? "" : " (" + a.reason() + ")"));
    });
  }
  Status Step(const StepInfo& info) override {
    auto ask = [&](const std::string& param, const std::string& value) {
      msg::ParamChange r;
      r.graph_name(graph_);
      r.component_name("slow");
      r.param_name(param);
      r.op("set");
      r.value(value);
      r.request_id(param + value);
      return out_->Publish(r);
    };
    if (info.index == 2) {
      if (Status s = ask("level", "5"); !s.ok()) return s;
      return ask("other", "7");
    }
    if (info.index == 4) return ask("level", "13");
    if (info.index == last_) return ask("level", "9");
    return Status::OK();
  }

 private:
  std::string graph_;
  uint64_t last_ = 1000;
  Output<msg::ParamChange>* out_ = nullptr;
};

void RegisterProbe(PluginRegistry& r) {
  r.Add<Probe>("probe");
  r.Add<Slow>("slow");
  r.Add<Asker>("asker");
}

class ExecutorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    g_log = &log_;
    ASSERT_TRUE(catalog_.Register("executor_test", &RegisterProbe).ok());
  }
  void TearDown() override { g_log = nullptr; }

  // Parses and validates `yaml`; runs it on a MemoryTransport. Returns Run()'s Status.
  Status Run(const std::string& yaml, uint64_t steps = 0, double duration_s = 0, bool spurious = false) {
    std::vector<Diagnostic> diags;
    graph_ = ParseGraph(yaml, "test.yaml", {}, &diags);
    resolved_ = ValidateGraph(graph_, catalog_, &diags);
    for (const auto& d : diags) ADD_FAILURE() << d.ToString();
    if (!diags.empty()) return Status::InvalidArgument("invalid test graph");
    Executor::Options o;
    o.process = "main";
    o.steps = steps;
    o.duration_s = duration_s;
    o.session = session_;
    o.stop_report_s = stop_report_s_;
    o.transport = [this, spurious](const std::string&, bool) -> StatusOr<std::unique_ptr<Transport>> {
      return std::unique_ptr<Transport>(new testing::MemoryTransport([this](const std::string& e) { log_.Add(e); }, spurious));
    };
    auto ex = std::make_unique<Executor>(graph_, resolved_, &catalog_, o);
    Status s = ex->Run();
    rows_ = ex->Report();
    ex.reset();
    return s;
  }
  // Lifecycle events in order (steps and receptions left out); checks that the transport was
  // destroyed before any component, then leaves component destructions out too (their relative
  // order is the container's business).
  std::vector<std::string> Lifecycle() {
    std::vector<std::string> out;
    bool transport_gone = false;
    for (const auto& e : log_.events) {
      if (e == "transport destroyed") transport_gone = true;
      if (e.ends_with(" destroyed") && e != "transport destroyed") {
        EXPECT_TRUE(transport_gone) << e << " before the transport";
        continue;
      }
      if (e.find(" step") == std::string::npos && e.find(" got") == std::string::npos) out.push_back(e);
    }
    return out;
  }
  const StepStats::Snapshot& Stats(const std::string& component) {
    for (const auto& r : rows_)
      if (r.component == component) return r.stats;
    ADD_FAILURE() << "no row for " << component;
    static StepStats::Snapshot none;
    return none;
  }

  EventLog log_;
  Catalog catalog_;
  Graph graph_;
  ResolvedGraph resolved_;
  std::vector<Executor::Row> rows_;
  std::function<std::unique_ptr<ProcessSession>()> session_;  // Run()'s (empty: none)
  double stop_report_s_ = 10;                                 // Run()'s Options::stop_report_s
};

const char* kPair = R"(graph: t
clock: stepped
components:
  a: {type: probe, rate_hz: 10, outputs: {out: ab}, params: {PA}}
  b: {type: probe, trigger: in, inputs: {in: ab}, outputs: {out: bout}, params: {PB}}
)";

std::string Pair(const std::string& pa = "", const std::string& pb = "", const std::string& clock = "stepped") {
  std::string y = kPair;
  y.replace(y.find("PA"), 2, pa);
  y.replace(y.find("PB"), 2, pb);
  y.replace(y.find("stepped"), 7, clock);
  return y;
}

TEST_F(ExecutorTest, TriggeredComponentStepsOncePerSampleInOrder) {
  ASSERT_TRUE(Run(Pair(), 5).ok());
  EXPECT_EQ(log_.Matching("b got"), (std::vector<std::string>{"b got 0", "b got 1", "b got 2", "b got 3", "b got 4"}));
  EXPECT_EQ(log_.Matching("b step").size(), 5u);
  EXPECT_EQ(Stats("a").steps, 5u);
  EXPECT_EQ(Stats("b").steps, 5u);
}

TEST_F(ExecutorTest, WallClockTriggeredStepsNeverOverlapAndSeeEverySample) {
  ASSERT_TRUE(Run(Pair("", "", "wall"), 20).ok());
  EXPECT_TRUE(log_.Matching("OVERLAPPING").empty());
  EXPECT_EQ(log_.Matching("b got").size(), 20u);
}

// A notification without a new sample (Fast DDS gives some) must not step a triggered component.
TEST_F(ExecutorTest, WallClockTriggerStepsOncePerSampleDespiteSpuriousNotifications) {
  ASSERT_TRUE(Run(Pair("", "", "wall"), 10, 0, /*spurious=*/true).ok());
  EXPECT_EQ(log_.Matching("b got").size(), 10u);
  EXPECT_EQ(Stats("b").steps, 10u);
}

TEST_F(ExecutorTest, LifecycleOrderAndThreads) {
  ASSERT_TRUE(Run(Pair(), 2).ok());
  EXPECT_EQ(Lifecycle(), (std::vector<std::string>{"a configure", "b configure", "a activate", "b activate",
                                                 "b deactivate (tapped 0)", "a deactivate (tapped 0)", "b shutdown",
                                                 "a shutdown", "transport destroyed"}));
  for (const auto& id : log_.lifecycle_threads) EXPECT_EQ(id, std::this_thread::get_id());
}

TEST_F(ExecutorTest, WallClockLifecycleRunsOnTheCallersThread) {
  ASSERT_TRUE(Run(Pair("", "", "wall"), 3).ok());
  ASSERT_EQ(log_.lifecycle_threads.size(), 8u);
  for (const auto& id : log_.lifecycle_threads) EXPECT_EQ(id, std::this_thread::get_id());
}

// A failure keeps its code; context names the component and phase; the teardown is complete.
struct PhaseFailure {
  const char* name;
  const char* pa;
  const char* pb;
  Status::Code code;
  const char* message;
  std::vector<std::string> lifecycle;
};

class ExecutorFailure : public ExecutorTest, public ::testing::WithParamInterface<PhaseFailure> {};

TEST_P(ExecutorFailure, KeepsTheCodeAndTearsDown) {
  const PhaseFailure& f = GetParam();
  Status s = Run(Pair(f.pa, f.pb), 5);
  EXPECT_EQ(s.code(), f.code) << s.ToString();
  EXPECT_EQ(s.message(), f.message);
  EXPECT_EQ(Lifecycle(), f.lifecycle);
}

INSTANTIATE_TEST_SUITE_P(
    Phases, ExecutorFailure,
    ::testing::Values(
        PhaseFailure{"Configure", "", "fail: configure, code: invalid", Status::Code::kInvalidArgument,
                     "b: configure failed: boom",
                     {"a configure", "b configure", "a shutdown", "transport destroyed"}},
        PhaseFailure{"Activate", "", "fail: activate, code: io", Status::Code::kIOError, "b: activate failed: boom",
                     {"a configure", "b configure", "a activate", "b activate", "a deactivate (tapped 0)", "b shutdown",
                      "a shutdown", "transport destroyed"}},
        PhaseFailure{"Step", "fail: step, code: dataloss, fail_step: 2", "", Status::Code::kDataLoss,
                     "a: step 2 failed: boom",
                     {"a configure", "b configure", "a activate", "b activate", "b deactivate (tapped 0)",
                      "a deactivate (tapped 0)", "b shutdown", "a shutdown", "transport destroyed"}},
        PhaseFailure{"Deactivate", "fail: deactivate, code: io", "", Status::Code::kIOError,
                     "a: deactivate failed: boom",
                     {"a configure", "b configure", "a activate", "b activate", "b deactivate (tapped 0)",
                      "a deactivate (tapped 0)", "b shutdown", "a shutdown", "transport destroyed"}}),
    [](const ::testing::TestParamInfo<PhaseFailure>& i) { return std::string(i.param.name); });

// A session that logs its calls and starts at once, as a graph of one process does (SoloSession).
class LoggingSession final : public ProcessSession {
 public:
  Status Open(Transport*) override { return Status::OK(); }
  Status AwaitMatched(const std::function<bool()>&) override {
    g_log->Add("session matched");
    return Status::OK();
  }
  StatusOr<int64_t> AwaitStart(const std::function<bool()>&) override {
    g_log->Add("session start");
    start_ns_ = WallNowNs();
    return start_ns_;
  }
  int64_t graph_start_ns() const override { return start_ns_; }
  void Started() override { g_log->Add("session started"); }
  Status Heartbeat() override { return Status::OK(); }
  void Stopping() override {}
  void Close() override {}
  bool shared_start() const override { return false; }

 private:
  int64_t start_ns_ = 0;
};

// The start is fixed after every Activate (issue #45 item 4): a component that waits there (the
// web component's wait for the subject's page, here 0.5 s) delays the clock; the first steps are
// not late by its wait (they were, each a deadline miss: the start came before Activate).
TEST_F(ExecutorTest, TheSessionsStartIsFixedOnceEveryComponentHasActivated) {
  session_ = [] { return std::make_unique<LoggingSession>(); };
  ASSERT_TRUE(Run(Pair("", "activate_ms: 500", "wall"), 3).ok());
  std::vector<std::string> order;
  for (const auto& e : log_.events)
    if (e.starts_with("session") || e.ends_with(" activate") || e == "a step 0") order.push_back(e);
  EXPECT_EQ(order, (std::vector<std::string>{"session matched", "a activate", "b activate", "session start", "session started",
                                             "a step 0"}));
  // Late by the 0.5 s Activate on the old order; a loaded machine stays far below that.
  EXPECT_LT(Stats("a").jitter_max_s, 0.3);
  EXPECT_EQ(Stats("a").steps, 3u);
}

// A stop that takes long says what it waits for, every stop_report_s (a Deactivate that never
// returned once left a study's graph running for minutes with nothing said); a quick one nothing.
TEST_F(ExecutorTest, AStopThatTakesLongSaysWhatItWaitsFor) {
  stop_report_s_ = 0.1;
  ::testing::internal::CaptureStderr();
  ASSERT_TRUE(Run(Pair("deactivate_ms: 350"), 3).ok());
  const std::string slow = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(std::regex_search(slow, std::regex(R"(still stopping after 0\.[1-3] s: deactivating 'a')"))) << slow;
  stop_report_s_ = 1;  // a quick stop, even on a loaded machine
  ::testing::internal::CaptureStderr();
  ASSERT_TRUE(Run(Pair(), 3).ok());
  const std::string quick = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(quick.find("still stopping"), std::string::npos) << quick;
}

TEST_F(ExecutorTest, TriggeredCycleIsCappedInOneInstant) {
  Status s = Run(R"(graph: t
clock: stepped
components:
  src: {type: probe, rate_hz: 10, outputs: {out: ping}}
  p: {type: probe, trigger: in, inputs: {in: ping}, outputs: {out: pong}}
  q: {type: probe, trigger: in, inputs: {in: pong}, outputs: {out: ping}}
)", 3);
  EXPECT_EQ(s.code(), Status::Code::kInternal);
  EXPECT_NE(s.message().find("kept triggering each other for 1000 rounds"), std::string::npos) << s.message();
  EXPECT_EQ(Stats("src").steps, 1u);
}

TEST_F(ExecutorTest, SteppedDurationIsSimulatedTime) {
  ASSERT_TRUE(Run(Pair("sleep_ms: 5"), 0, 0.35).ok());  // 100 ms period: steps at 0, 0.1, 0.2, 0.3 s
  EXPECT_EQ(Stats("a").steps, 4u);
}

// A slow triggered component steps inside its upstream's Publish(): its time is its own.
TEST_F(ExecutorTest, SlowDownstreamIsChargedToItself) {
  ASSERT_TRUE(Run(Pair("", "sleep_ms: 20", "wall"), 10).ok());
  EXPECT_GE(Stats("b").mean_s, 0.019);
  // The upstream does nothing but publish: far below the downstream's 20 ms (loaded machine: 5 ms).
  EXPECT_LT(Stats("a").max_s, 0.005) << "upstream charged with its downstream's time";
  EXPECT_EQ(Stats("a").deadline_misses, 0u);
}

// A serialized subscription's callback (a recorder's) is charged to the subscriber, not to the
// step whose Publish() delivers it.
TEST_F(ExecutorTest, SerializedCallbackIsChargedToTheSubscriber) {
  ASSERT_TRUE(Run(R"(graph: t
clock: stepped
components:
  a: {type: probe, rate_hz: 10, outputs: {out: ab}}
  rec: {type: probe, rate_hz: 1, params: {tap: ab, sleep_ms: 10}}
)", 5).ok());
  EXPECT_EQ(Stats("rec").deliveries, 5u);
  EXPECT_GE(Stats("rec").delivery_mean_s, 0.009);
  EXPECT_LT(Stats("a").max_s, 0.005) << "publisher charged with its subscriber's callback";
}

// An on-demand subscription calls back only between Start() and Stop(): a viewer with no client
// costs its publishers nothing.
TEST_F(ExecutorTest, OnDemandSubscriptionDeliversOnlyBetweenStartAndStop) {
  ASSERT_TRUE(Run(R"(graph: t
clock: stepped
components:
  a: {type: probe, rate_hz: 10, outputs: {out: ab}}
  viewer: {type: probe, rate_hz: 10, params: {tap: ab, tap_start: 3, tap_stop: 6}}
)", 10).ok());
  // a publishes before the viewer steps at each instant: samples 4, 5 and 6 only.
  EXPECT_EQ(Stats("viewer").deliveries, 3u);
  EXPECT_EQ(log_.Matching("viewer deactivate"), (std::vector<std::string>{"viewer deactivate (tapped 3)"}));
}

// A prepared live param on the wall clock: its preparation runs while the component steps on
// (its other live params held still), the value takes effect at a step boundary after it ended
// (committed there), the component's next request waits for it (answered in order), a refused
// preparation leaves the old value, and a run that stops during one refuses it without waiting
// for a step that never comes.
TEST_F(ExecutorTest, APreparedLiveParamIsPreparedOffTheStepThreadAndAppliedInOrder) {
  ASSERT_TRUE(Run(R"(graph: t
clock: wall
components:
  asker: {type: asker, rate_hz: 20, params: {last: 24}, outputs: {requests: dyad/param_requests}}
  slow: {type: slow, rate_hz: 20, params: {prepare_ms: 300}}
)", 0, 1.6).ok());
  const std::vector<std::string> steps = log_.Matching("slow step");
  ASSERT_GE(steps.size(), 20u);
  int while_preparing = 0, first_five = -1, first_seven = -1;
  for (size_t i = 0; i < steps.size(); ++i) {
    while_preparing += steps[i].ends_with("while preparing");
    if (first_five < 0 && steps[i].find("level 5") != std::string::npos) first_five = static_cast<int>(i);
    if (first_seven < 0 && steps[i].find("other 7") != std::string::npos) first_seven = static_cast<int>(i);
    EXPECT_EQ(steps[i].find("level 13"), std::string::npos) << steps[i] << ": a refused value took effect";
    EXPECT_EQ(steps[i].find("level 9"), std::string::npos) << steps[i] << ": the run stopped before it was prepared";
  }
  EXPECT_GE(while_preparing, 4) << "300 ms of preparation at 20 Hz: the component stepped on meanwhile";
  ASSERT_GE(first_five, 6) << "level 5 applied after its 300 ms preparation (asked at step 2)";
  EXPECT_GE(first_seven, first_five) << "other 7 came after level 5: it waited for it";
  EXPECT_NE(steps.back().find("level 5 other 7"), std::string::npos) << steps.back();
  EXPECT_EQ(log_.Matching("slow commit"), (std::vector<std::string>{"slow commit 5"}));
  EXPECT_EQ(log_.Matching("answer "),
            (std::vector<std::string>{"answer applied level 5", "answer applied other 7", "answer refused level 13 (unlucky)",
                                      "answer refused level 9 (the run stopped before the change took effect)"}));
}

TEST(SubscribeSerializedOnDemand, IsUnimplementedOnAContextOfTheTests) {
  struct FakeContext final : Context {
    const std::string& name() const override { return name_; }
    const Params& params() const override { return params_; }
    const Clock& clock() const override { std::abort(); }
    Logger& log() override { std::abort(); }
    uint64_t seed() const override { return 0; }
    int64_t period_ns() const override { return 0; }
    void RequestStop(std::string) override {}
    InputBase* FindInput(std::string_view, const TypeInfo&) override { return nullptr; }
    OutputBase* FindOutput(std::string_view, const TypeInfo&) override { return nullptr; }
    std::string name_ = "fake";
    Params params_;
  } ctx;
  auto s = SubscribeSerializedOnDemand(ctx, "ab", [](const SerializedSample&) {});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().code(), Status::Code::kUnimplemented);
}

}  // namespace
}  // namespace dyad
