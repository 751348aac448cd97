#include "exec/executor.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include <dyad/msg/types.hpp>
#include <dyad/run_stopping.hpp>
#include <dyad/security.hpp>

#include "dds/dds_participant.hpp"
#include "exec/logger.hpp"
#include "exec/step_clock.hpp"
#include "exec/wall_clock.hpp"
#include "graph/graph_topics.hpp"
#include "graph/run_partition.hpp"

namespace dyad {
namespace {

int64_t SteadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The topic the graph binds `port` to; empty when unbound.
std::string BoundTopic(const std::vector<PortBinding>& bindings, const std::string& port) {
  for (const auto& b : bindings)
    if (b.port == port) return b.topic;
  return "";
}

// Time spent in steps and callbacks nested inside the current one on this thread (a triggered
// component steps inside its upstream's Publish(), a recorder's callback too): each region
// charges its whole duration to the enclosing one, which subtracts it from its own time.
struct NestFrame {
  int64_t nested_ns = 0;
  NestFrame* parent = nullptr;
};
// initial-exec: a plain TLS access, not a __tls_get_addr call per step (the library is linked
// by its programs, never only dlopen()ed; glibc keeps room for one that is).
thread_local NestFrame* t_frame __attribute__((tls_model("initial-exec"))) = nullptr;

class NestedTimer {
 public:
  NestedTimer() : start_(StepClockNow()) {
    frame_.parent = t_frame;
    t_frame = &frame_;
  }
  NestedTimer(const NestedTimer&) = delete;
  NestedTimer& operator=(const NestedTimer&) = delete;
  ~NestedTimer() {
    if (!stopped_) Stop();
  }
  // The start, steady and wall time (exec/step_clock.hpp: one reading for both).
  const ClockReading& start() const { return start_; }
  // Ends the region; returns its own time (its duration minus the regions nested in it).
  int64_t Stop() {
    stopped_ = true;
    const int64_t total = StepClockNow().steady_ns - start_.steady_ns;
    t_frame = frame_.parent;
    if (frame_.parent != nullptr) frame_.parent->nested_ns += total;
    return total - frame_.nested_ns;
  }

 private:
  NestFrame frame_;
  ClockReading start_;
  bool stopped_ = false;
};

}  // namespace

class Executor::ClockImpl final : public Clock {
 public:
  explicit ClockImpl(bool stepped) : stepped_(stepped) {}
  // Wall time from the step path's clock (exec/step_clock.hpp: a wall-clock step shows within 1 ms).
  int64_t now_ns() const override { return At(StepClockNow()); }
  // The clock's time at `reading` (taken just before): simulated time in a stepped run.
  int64_t At(const ClockReading& reading) const {
    if (stepped_) return sim_ns_.load(std::memory_order_acquire);
    return reading.wall_ns;
  }
  void Set(int64_t t) { sim_ns_.store(t, std::memory_order_release); }
  bool stepped() const { return stepped_; }

 private:
  bool stepped_;
  std::atomic<int64_t> sim_ns_{0};
};

struct Executor::Instance {
  const ResolvedComponent* rc = nullptr;
  std::unique_ptr<Component> component;
  std::unique_ptr<ContextImpl> ctx;
  std::vector<std::unique_ptr<InputBase>> inputs;
  std::vector<std::unique_ptr<OutputBase>> outputs;
  std::vector<SerializedSubscription*> serialized_readers;  // owned by the transport
  bool configuring = false;  // generic-topic calls are allowed only in Configure()
  TypedReader* trigger = nullptr;                            // owned by the transport
  InputBase* trigger_port = nullptr;                         // the trigger's input (in `inputs`)
  StepStats stats;
  std::atomic<bool> active{false};
  // Triggered steps (TriggerStep): deliveries not yet answered by a step; not 0 while one steps.
  std::atomic<uint64_t> notes{0};
  uint64_t index = 0;
  size_t slot = 0;  // in instances_ (and LiveParams' targets)
  Params params;    // the component's ctx.params(): live ones change at step boundaries
  LiveParams::Target live;
  bool configured = false;
  bool activated = false;
  std::thread thread;
  const std::string& name() const { return rc->config->name; }
};

class Executor::ContextImpl final : public Context, public detail::ContextExtensions, public detail::RunStoppingQuery {
 public:
  ContextImpl(Executor* ex, Instance* inst)
      : ex_(ex), inst_(inst), logger_(inst->name()), seed_(ComponentSeed(ex->graph_.seed, inst->name())) {}
  const std::string& name() const override { return inst_->name(); }
  const Params& params() const override { return inst_->params; }
  void CheckLiveParam(const std::string& name, LiveParamCheck check) override {
    if (inst_->configuring) inst_->live.checks[name] = std::move(check);
  }
  void PrepareLiveParam(const std::string& name, LiveParamPrepare prepare, LiveParamCommit commit) override {
    if (inst_->configuring) inst_->live.prepares[name] = {std::move(prepare), std::move(commit)};
  }
  const Clock& clock() const override { return *ex_->clock_; }
  Logger& log() override { return logger_; }
  uint64_t seed() const override { return seed_; }
  int64_t period_ns() const override { return inst_->rc->period_ns; }
  void RequestStop(std::string reason) override {
    // A run that ends by itself says why, once (the first reason is the one that holds).
    if (ex_->RequestStop(inst_->name() + ": " + reason)) logger_.Info("ends the run: " + reason);
  }
  bool run_stopping() const override { return ex_->stopping(); }

  const std::string& graph_name() const override { return ex_->graph_.name; }
  const std::string& graph_yaml() const override { return ex_->graph_yaml_; }
  const std::string& graph_folder() const override { return ex_->graph_.folder; }
  bool stepped() const override { return ex_->clock_->stepped(); }
  const std::vector<TopicInfo>& graph_topics() const override { return ex_->topics_; }
  const TypeInfo* FindMessageType(std::string_view name) const override {
    for (const auto& t : ex_->topics_)
      if (t.type->name == name || t.type->short_name() == name) return t.type;
    return ex_->catalog_ ? ex_->catalog_->FindMessageType(std::string(name)) : nullptr;
  }
  Status SubscribeSerialized(const std::string& topic, SerializedCallback callback) override {
    auto r = Subscribe("SubscribeSerialized", topic, std::move(callback), /*on_demand=*/false);
    return r.ok() ? Status::OK() : r.status();
  }
  StatusOr<OnDemandSubscription*> SubscribeSerializedOnDemand(const std::string& topic, SerializedCallback callback) override {
    auto r = Subscribe("SubscribeSerializedOnDemand", topic, std::move(callback), /*on_demand=*/true);
    if (!r.ok()) return r.status();
    return static_cast<OnDemandReader*>(r.value());
  }
  StatusOr<SerializedWriter*> AdvertiseSerialized(const std::string& topic, const TypeInfo& type) override {
    if (!inst_->configuring) return Status::FailedPrecondition(inst_->name() + ": AdvertiseSerialized('" + topic + "') outside Configure()");
    TopicQos qos;
    if (const TopicInfo* info = ex_->FindTopic(topic)) {
      if (info->type->name != type.name)
        return Status::InvalidArgument("topic '" + topic + "' carries " + info->type->name + " in graph '" + ex_->graph_.name +
                                       "', not " + type.name);
      // The graph's QoS for the topic, all of it (a writer offering less liveliness than the
      // graph's readers request would never match them).
      auto rt = ex_->resolved_.topics.find(topic);
      qos = rt != ex_->resolved_.topics.end()
                ? QosOf(rt->second)
                : TopicQos{info->reliable ? Reliability::kReliable : Reliability::kBestEffort, info->depth, info->deadline_ms, false};
    }
    auto w = ex_->transport_->CreateSerializedWriter(topic, type, qos, ex_->clock_.get());
    if (!w.ok()) return w.status().WithContext(inst_->name() + ": AdvertiseSerialized('" + topic + "')");
    return w.value();
  }

 protected:
  InputBase* FindInput(std::string_view port, const TypeInfo& type) override {
    const auto& ins = inst_->rc->entry->spec.inputs();
    for (size_t i = 0; i < ins.size(); ++i)
      if (ins[i].name == port) {
        if (ins[i].type->name != type.name) Abort("input", port, type);
        return inst_->inputs[i].get();
      }
    Abort("input", port, type);
  }
  OutputBase* FindOutput(std::string_view port, const TypeInfo& type) override {
    const auto& outs = inst_->rc->entry->spec.outputs();
    for (size_t i = 0; i < outs.size(); ++i)
      if (outs[i].name == port) {
        if (outs[i].type->name != type.name) Abort("output", port, type);
        return inst_->outputs[i].get();
      }
    Abort("output", port, type);
  }

 private:
  // A serialized subscription for the component; `on_demand`: created stopped, KEEP_LAST.
  StatusOr<SerializedSubscription*> Subscribe(const char* call, const std::string& topic, SerializedCallback callback,
                                              bool on_demand) {
    const std::string what = inst_->name() + ": " + call + "('" + topic + "')";
    if (!inst_->configuring) return Status::FailedPrecondition(what + " outside Configure()");
    const TopicInfo* info = ex_->FindTopic(topic);
    if (info == nullptr) return Status::NotFound("topic '" + topic + "' is not a topic of graph '" + ex_->graph_.name + "'");
    // KEEP_ALL: the reader never drops a sample (on demand, a viewer's: the topic's depth).
    // Reliability follows the topic's writers, except that writers all in this process deliver
    // synchronously inside write(): a BEST_EFFORT reader then loses nothing and costs a third of
    // a RELIABLE one (bench/recorder).
    const bool reliable = info->reliable && !info->writers_local;
    TopicQos qos{reliable ? Reliability::kReliable : Reliability::kBestEffort,
                 on_demand ? std::max(info->depth, 1) : info->depth, 0, !on_demand};
    if (auto rt = ex_->resolved_.topics.find(topic); rt != ex_->resolved_.topics.end())
      qos.ros2_name = QosOf(rt->second).ros2_name;  // a ROS 2 topic is read where ROS 2 writes it
    // The callback's time is the subscriber's, not that of the step whose Publish() delivers it.
    StepStats* stats = &inst_->stats;
    SerializedCallback timed = [cb = std::move(callback), stats](const SerializedSample& sample) {
      NestedTimer timer;
      cb(sample);
      stats->RecordDelivery(timer.Stop());
    };
    if (on_demand) {
      auto d = ex_->transport_->CreateOnDemandReader(topic, *info->type, qos, ex_->clock_.get(), std::move(timed));
      if (!d.ok()) return d.status().WithContext(what);
      inst_->serialized_readers.push_back(d.value());
      return static_cast<SerializedSubscription*>(d.value());
    }
    auto r = ex_->transport_->CreateSerializedReader(topic, *info->type, qos, ex_->clock_.get(), std::move(timed));
    if (!r.ok()) return r.status().WithContext(what);
    inst_->serialized_readers.push_back(r.value());
    return r;
  }
  [[noreturn]] void Abort(const char* kind, std::string_view port, const TypeInfo& type) {
    std::fprintf(stderr, "dyad: component '%s' (%s) asked for %s '%.*s' of type %s, which it did not declare so\n",
                 inst_->name().c_str(), inst_->rc->config->type.c_str(), kind, static_cast<int>(port.size()), port.data(),
                 type.name.c_str());
    std::abort();
  }
  Executor* ex_;
  Instance* inst_;
  StderrLogger logger_;
  uint64_t seed_;
};

Executor::Executor(const Graph& graph, const ResolvedGraph& resolved, const Catalog* catalog, Options options)
    : graph_(graph), resolved_(resolved), catalog_(catalog), options_(std::move(options)),
      graph_yaml_(RedactedGraphYaml(graph, resolved)),
      clock_(std::make_unique<ClockImpl>(graph.clock == ClockMode::kStepped)) {}

Executor::~Executor() {
  stop_.store(true, std::memory_order_release);
  cv_.notify_all();
  for (auto& inst : instances_) {
    inst->active.store(false, std::memory_order_release);
    if (inst->thread.joinable()) inst->thread.join();
  }
  if (live_params_) live_params_->Stop();  // its preparer may be inside a component
  // The transport first (no callback after it), then components and ports (member order).
  if (session_) session_->Close();  // its threads write on the transport's endpoints
  transport_.reset();
}

bool Executor::RequestStop(const std::string& reason) {
  bool first = false;
  {
    MutexLock lock(mutex_);
    first = stop_reason_.empty();
    if (first) stop_reason_ = reason;
    stop_.store(true, std::memory_order_release);
  }
  cv_.notify_all();
  return first;
}

void Executor::Fail(const Status& status) {
  {
    MutexLock lock(mutex_);
    if (failure_.ok()) failure_ = status;
  }
  RequestStop("failure: " + status.message());
}

Status Executor::Setup() {
  // The step clock's origin: its TSC calibration starts here, long before the first step, and
  // its one file read (the kernel's clocksource) is not on a step thread.
  (void)detail::StepClockUsesTsc();
  if (Status s = CreateTransport(); !s.ok()) return s;
  for (const auto& rc : resolved_.components) {
    if (graph_.ProcessOf(*rc.config) != options_.process) continue;
    auto inst = std::make_unique<Instance>();
    inst->rc = &rc;
    inst->slot = instances_.size();
    inst->params = rc.params;
    if (Status s = BindPorts(*inst); !s.ok()) return s;
    inst->ctx = std::make_unique<ContextImpl>(this, inst.get());
    inst->component = rc.entry->type.create();
    instances_.push_back(std::move(inst));
  }
  if (instances_.empty()) return Status::InvalidArgument("no component is placed in process '" + options_.process + "'");

  if (!options_.guest) {
    std::vector<LiveParams::Target*> targets;
    for (auto& inst : instances_) {
      inst->live = {inst->name(), &inst->rc->entry->spec, &inst->params, &inst->index, &inst->ctx->log(), {}, {}};
      targets.push_back(&inst->live);
    }
    live_params_ = std::make_unique<LiveParams>();
    if (Status s = live_params_->Open(transport_.get(), graph_.name, options_.process, clock_.get(), graph_.folder,
                                         clock_->stepped(), std::move(targets)); !s.ok())
      return s;
  }
  // The runtime's own output: timing of this process's components.
  if (!options_.guest) {
    auto w = CreateRuntimeWriter(transport_.get(), runtime_topics::kStats);
    if (!w.ok()) return w.status();
    stats_output_ = std::make_unique<Output<msg::ComponentStats>>();
    stats_output_->Bind("stats", runtime_topics::kStats.name, "dyad/" + options_.process, w.value(), clock_.get());
  }

  if (options_.session) session_ = options_.session();
  if (session_)
    if (Status s = session_->Open(transport_.get()); !s.ok()) return s;

  BuildTopicList();
  for (auto& inst : instances_) {
    inst->configuring = true;
    Status s = inst->component->Configure(*inst->ctx);
    inst->configuring = false;
    if (!s.ok()) return s.WithContext(inst->name() + ": configure failed");
    inst->configured = true;
  }
  return Status::OK();
}

// The options' transport (tests), or a DDS participant named dyad/<graph>/<process> in the run's
// partition: this process only in a stepped run, the network otherwise.
Status Executor::CreateTransport() {
  const bool stepped = clock_->stepped();
  const std::string participant_name = "dyad/" + graph_.name + "/" + options_.process;
  if (options_.transport) {
    auto t = options_.transport(participant_name, stepped);
    if (!t.ok()) return t.status();
    transport_ = std::move(t.value());
    return Status::OK();
  }
  DdsParticipant::Options po;
  po.scope = stepped ? DdsParticipant::Scope::kProcessOnly : DdsParticipant::Scope::kNetwork;
  po.network = graph_.network;
  po.process = options_.process;
  po.partitions = {RunPartition(graph_)};
  // A keystore subset of another machine does not hold this process's identity: say which does.
  if (Status s = CheckIdentityHeld(graph_, ProcessIdentity(options_.process)); !s.ok()) return s;
  po.security = IdentityOf(graph_, ProcessIdentity(options_.process));
  po.on_problem = [this](const std::string& msg) {
    ++problems_;
    StderrLogger("dds").Error(msg);
  };
  po.on_foreign_writer = [this](const std::string& msg) {
    ++foreign_writers_;
    StderrLogger("dds").Warn(msg);
  };
  auto p = DdsParticipant::Create(graph_.domain_id, participant_name, std::move(po));
  if (!p.ok()) return p.status();
  transport_ = std::move(p.value());
  return Status::OK();
}

// A reader for each bound input (whose arrival steps the component when it is the trigger, in
// wall-clock runs) and a writer for each bound output; unbound ports stay empty.
Status Executor::BindPorts(Instance& inst) {
  const ComponentConfig& config = *inst.rc->config;
  const ComponentSpec& spec = inst.rc->entry->spec;
  const bool stepped = clock_->stepped();
  Instance* raw = &inst;
  for (const auto& ps : spec.inputs()) {
    auto port = ps.make_input();
    const std::string topic = BoundTopic(config.inputs, ps.name);
    TypedReader* reader = nullptr;
    if (!topic.empty()) {
      std::function<void()> on_data;
      if (!stepped && config.trigger == ps.name) on_data = [this, raw] { TriggerStep(*raw); };
      auto r = transport_->CreateReader(topic, *ps.type, QosOf(resolved_.topics.at(topic)), on_data);
      if (!r.ok()) return r.status().WithContext(config.name + "." + ps.name);
      reader = r.value();
      if (config.trigger == ps.name) {
        inst.trigger = reader;
        inst.trigger_port = port.get();
      }
    }
    port->Bind(ps.name, topic, reader);
    inst.inputs.push_back(std::move(port));
  }
  for (const auto& ps : spec.outputs()) {
    auto port = ps.make_output();
    const std::string topic = BoundTopic(config.outputs, ps.name);
    TypedWriter* writer = nullptr;
    if (!topic.empty()) {
      auto w = transport_->CreateWriter(topic, *ps.type, QosOf(resolved_.topics.at(topic)));
      if (!w.ok()) return w.status().WithContext(config.name + "." + ps.name);
      writer = w.value();
    }
    port->Bind(ps.name, topic, config.name, writer, clock_.get());
    inst.outputs.push_back(std::move(port));
  }
  return Status::OK();
}

// A triggered step polls its trigger's input first and is not taken when that brought nothing
// new: Fast DDS also notifies when nothing new is left to take (measured: a triggered mixer
// stepped 86 times for 61 intentions), and a step for nothing would, e.g., let a rate-limited
// mixer move the robot further per period than allowed. (Asking the reader for its unread count
// first cost a lock of our own and one of Fast DDS's per step: bench_pingpong.)
Status Executor::StepOnce(Instance& inst, int64_t scheduled_steady_ns, bool periodic) {
  NestedTimer timer;
  const int64_t t0 = timer.start().steady_ns;
  const int64_t now = clock_->At(timer.start());
  InputBase* const first = periodic ? nullptr : inst.trigger_port;
  if (first != nullptr && first->Poll(now) == 0) return Status::OK();
  if (live_params_) live_params_->BeforeStep(inst.slot);
  for (auto& in : inst.inputs)
    if (in.get() != first) in->Poll(now);
  Status s = inst.component->Step(StepInfo{now, inst.index++, inst.rc->period_ns});
  const int64_t own = timer.Stop();
  int64_t jitter = 0;
  bool missed = false;
  if (periodic && !clock_->stepped()) {
    const int64_t late = t0 - scheduled_steady_ns;
    jitter = std::abs(late);
    // Downstream work nested in this step is charged to the downstream components; if it delays
    // this component's next period, that shows as this component's start jitter.
    missed = std::max<int64_t>(late, 0) + own > inst.rc->period_ns;
  }
  inst.stats.Record(own, jitter, missed);
  if (!s.ok()) return s.WithContext(inst.name() + ": step " + std::to_string(inst.index - 1) + " failed");
  return s;
}

// Each delivery adds a note; the one that finds none steps the component, again as long as notes
// came during its step, and clears them with a compare-exchange that fails if another came
// meanwhile. Every change of `notes` is a read-modify-write of that one word, so a delivery and
// the stepping thread's last look cannot miss each other (two flags, a store of one then a load
// of the other on each side, can: a store-load reordering, and a delivery's step was lost). Cost:
// two atomic read-modify-writes for a step, one for a delivery that finds the component busy.
// All sequentially consistent, as the loads of `active` and stop_ here and the stores in Run(),
// which then waits for `notes` to be 0: a step either sees the stop or is waited for.
void Executor::TriggerStep(Instance& inst) {
  uint64_t seen = inst.notes.fetch_add(1) + 1;
  if (seen != 1) return;  // another thread is stepping it and will see this note
  for (;;) {
    // A notification is not a sample: StepOnce steps only if the trigger brought one.
    if (inst.active.load() && !stop_.load()) {
      if (Status s = StepOnce(inst, 0, false); !s.ok()) Fail(s);  // stops the run: no more steps
    }
    if (inst.notes.compare_exchange_strong(seen, 0)) return;  // else `seen` holds the notes now
  }
}

void Executor::PeriodicLoop(Instance& inst) {
  const int64_t period = inst.rc->period_ns;
  int64_t next = start_steady_ns_;
  std::unique_lock<std::mutex> lock(mutex_.native(), std::defer_lock);  // stop_ only: nothing guarded
  while (!stopping()) {
    lock.lock();
    cv_.wait_until(lock, std::chrono::steady_clock::time_point(std::chrono::nanoseconds(next)), [&] { return stopping(); });
    lock.unlock();
    if (stopping()) break;
    Status s = StepOnce(inst, next, true);
    if (!s.ok()) {
      Fail(s);
      break;
    }
    if (options_.steps > 0 && inst.index >= options_.steps) RequestStop("reached " + std::to_string(options_.steps) + " steps");
    next += period;
    const int64_t now = SteadyNs();
    if (now > next) next += ((now - next) / period + 1) * period;  // skip missed periods, don't burst
  }
}

Status Executor::RunStepped() {
  struct Due {
    Instance* inst;
    int64_t next;
  };
  std::vector<Due> periodic;
  std::vector<Instance*> triggered;
  for (auto& inst : instances_) {
    if (inst->rc->period_ns > 0) periodic.push_back({inst.get(), 0});
    else triggered.push_back(inst.get());
  }
  if (periodic.empty()) return Status::InvalidArgument("stepped clock needs at least one periodic component (rate_hz)");
  int64_t fastest = periodic.front().inst->rc->period_ns;
  for (const auto& d : periodic) fastest = std::min(fastest, d.inst->rc->period_ns);
  // Both limits count simulated time, so a stepped run is the same whatever the machine's load.
  const int64_t steps_end = options_.steps > 0 ? static_cast<int64_t>(options_.steps) * fastest : INT64_MAX;
  const int64_t duration_end = options_.duration_s > 0 ? static_cast<int64_t>(std::llround(options_.duration_s * 1e9)) : INT64_MAX;
  int64_t last_stats = SteadyNs();

  auto run_triggered = [&]() -> Status {
    for (int round = 0; round < 1000; ++round) {
      bool any = false;
      for (Instance* t : triggered) {
        if (t->trigger == nullptr || t->trigger->Unread() == 0) continue;
        any = true;
        if (Status s = StepOnce(*t, 0, false); !s.ok()) return s;
      }
      if (!any) return Status::OK();
    }
    return Status::Internal("triggered components kept triggering each other for 1000 rounds in one instant");
  };

  while (!stopping()) {
    int64_t t = INT64_MAX;
    for (const auto& d : periodic) t = std::min(t, d.next);
    if (t >= steps_end) {
      RequestStop("reached " + std::to_string(options_.steps) + " steps");
      break;
    }
    if (t >= duration_end) {
      RequestStop("reached the duration (simulated time)");
      break;
    }
    clock_->Set(t);
    for (auto& d : periodic) {
      if (d.next != t) continue;
      if (Status s = StepOnce(*d.inst, 0, true); !s.ok()) return s;
      if (Status s = run_triggered(); !s.ok()) return s;
      d.next += d.inst->rc->period_ns;
      if (stopping()) break;
    }
    if (options_.stats_period_s > 0 && SteadyNs() - last_stats > static_cast<int64_t>(options_.stats_period_s * 1e9)) {
      PublishStats();
      last_stats = SteadyNs();
    }
  }
  return Status::OK();
}

Status Executor::RunWall() {
  if (session_) {
    if (start_wall_ns_ == 0) return Status::OK();  // stopped while waiting for the start
    start_steady_ns_ = SteadyNs() + (start_wall_ns_ - WallNowNs());
    session_->Started();
  } else {
    start_steady_ns_ = SteadyNs();
  }
  const int64_t start_wall_ns = start_wall_ns_;
  for (auto& inst : instances_)
    if (inst->rc->period_ns > 0) inst->thread = std::thread([this, i = inst.get()] { PeriodicLoop(*i); });
  // A triggered component may have missed samples delivered before it was active.
  for (auto& inst : instances_)
    if (inst->trigger != nullptr && inst->trigger->Unread() > 0) TriggerStep(*inst);
  const auto start = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(start_steady_ns_));
  // 0: no end. With several processes both limits count from the graph's start, so a process
  // that joined late (restarted) ends with the others (at once when that end has passed), and one
  // without the fastest component a second after the last step.
  int64_t duration_ns = options_.duration_s > 0 ? static_cast<int64_t>(std::min(options_.duration_s, 1e9) * 1e9) : 0;
  if (session_ && session_->shared_start()) {
    const int64_t late = start_wall_ns - session_->graph_start_ns();
    if (duration_ns > 0) duration_ns = std::max<int64_t>(duration_ns - late, 1);
    if (options_.steps > 0) {
      const int64_t period = FastestPeriodNs();
      const int64_t steps = static_cast<int64_t>(std::min<uint64_t>(options_.steps, INT64_MAX / 4 / std::max<int64_t>(period, 1)));
      const int64_t by_steps =
          std::max<int64_t>(steps * period + (HoldsFastestComponent() ? period / 2 : 1'000'000'000) - late, 1);
      duration_ns = duration_ns > 0 ? std::min(duration_ns, by_steps) : by_steps;
    }
  }
  std::unique_lock<std::mutex> lock(mutex_.native());  // stop_ only: nothing guarded
  while (!stopping()) {
    auto wake = std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int64_t>(options_.stats_period_s * 1000));
    if (duration_ns > 0) {
      const auto end = start + std::chrono::nanoseconds(duration_ns);
      if (end < wake) wake = end;
    }
    cv_.wait_until(lock, wake, [&] { return stopping(); });
    if (stopping()) break;
    if (duration_ns > 0 && std::chrono::steady_clock::now() - start >= std::chrono::nanoseconds(duration_ns)) {
      lock.unlock();
      RequestStop(options_.duration_s > 0 ? "duration reached" : "the graph's fastest component reached its steps");
      lock.lock();
      break;
    }
    lock.unlock();
    PublishStats();
    lock.lock();
  }
  lock.unlock();
  for (auto& inst : instances_)
    if (inst->thread.joinable()) inst->thread.join();
  return Status::OK();
}

Status Executor::ActivateAll() {
  for (auto& inst : instances_) {
    if (Status s = inst->component->Activate(); !s.ok()) return s.WithContext(inst->name() + ": activate failed");
    inst->activated = true;
    inst->active.store(true, std::memory_order_release);
  }
  return Status::OK();
}

namespace {

// While Run() stops: every `period` that the stop is still under way, one line on stderr saying
// what it waits for. Seen once in a study under heavy load: a graph recorded its trial and never
// exited, and nothing said where it stood.
class StopReporter {
 public:
  explicit StopReporter(double period_s)
      : period_(std::chrono::duration<double>(period_s)), start_(std::chrono::steady_clock::now()), thread_([this] { Loop(); }) {}
  ~StopReporter() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  StopReporter(const StopReporter&) = delete;
  StopReporter& operator=(const StopReporter&) = delete;
  void At(std::string what) {
    std::lock_guard<std::mutex> lock(mutex_);
    what_ = std::move(what);
  }

 private:
  void Loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!cv_.wait_for(lock, period_, [this] { return done_; })) {
      char waited[32];
      std::snprintf(waited, sizeof waited, "%.1f",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
      StderrLogger("dyad").Warn(std::string("still stopping after ") + waited + " s: " + what_);
    }
  }
  const std::chrono::duration<double> period_;
  const std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;
  std::string what_ = "stopping";
  std::thread thread_;  // last: started once the rest is made
};

}  // namespace

Status Executor::Run() {
  Status s = Setup();
  const auto is_stopping = [this] { return stopping(); };
  // Several processes: nobody activates (and may publish) before its endpoints have matched.
  if (s.ok() && session_) s = session_->AwaitMatched(is_stopping);
  if (s.ok() && !(session_ && stopping())) s = ActivateAll();
  // The start is fixed once every component is active (with several processes, once every
  // process is): an Activate that waits (the web component's wait for the subject's page)
  // delays the clock instead of making every first step late by the wait.
  if (s.ok() && session_ && !stopping()) {
    auto start = session_->AwaitStart(is_stopping);
    if (start.ok()) start_wall_ns_ = start.value();
    else s = start.status();
  }
  if (s.ok()) {
    Status r = clock_->stepped() ? RunStepped() : RunWall();
    if (!r.ok()) Fail(r);
  }
  if (session_) session_->Stopping();
  // Stop: no more triggered steps, wait for any in flight, then deactivate in reverse order
  // (sequentially consistent: see TriggerStep).
  stop_.store(true);
  cv_.notify_all();
  StopReporter reporter(options_.stop_report_s);
  for (auto& inst : instances_) {
    inst->active.store(false);
    reporter.At("waiting for the step of '" + inst->name() + "' to end");
    if (inst->thread.joinable()) inst->thread.join();
    while (inst->notes.load() != 0) std::this_thread::yield();
  }
  reporter.At("stopping the live parameters' preparations, publishing the last stats");
  if (live_params_) live_params_->Stop();  // no preparation runs inside a component deactivating
  // The last stats, while every subscriber (a recorder) still listens.
  if (stats_output_) PublishStats();
  for (auto it = instances_.rbegin(); it != instances_.rend(); ++it) {
    Instance& inst = **it;
    reporter.At("closing the subscriptions of '" + inst.name() + "'");
    for (auto& r : inst.serialized_readers) r->Close();
    if (!inst.activated) continue;
    reporter.At("deactivating '" + inst.name() + "'");
    Status d = inst.component->Deactivate();
    if (!d.ok() && s.ok()) s = d.WithContext(inst.name() + ": deactivate failed");
  }
  for (auto it = instances_.rbegin(); it != instances_.rend(); ++it) {
    reporter.At("shutting down '" + (*it)->name() + "'");
    if ((*it)->configured) (*it)->component->Shutdown();
  }
  MutexLock lock(mutex_);
  if (!s.ok()) return s;
  return failure_;
}


int64_t Executor::FastestPeriodNs() const {
  int64_t fastest = 0;
  for (const auto& rc : resolved_.components)
    if (rc.period_ns > 0 && (fastest == 0 || rc.period_ns < fastest)) fastest = rc.period_ns;
  return fastest;
}

bool Executor::HoldsFastestComponent() const {
  for (const auto& inst : instances_)
    if (inst->rc->period_ns > 0 && inst->rc->period_ns == FastestPeriodNs()) return true;
  return false;
}

void Executor::PublishStats() {
  if (session_ && !stopping())
    if (Status s = session_->Heartbeat(); !s.ok()) Fail(s);
  if (!stats_output_) return;
  auto* out = static_cast<Output<msg::ComponentStats>*>(stats_output_.get());
  for (const auto& inst : instances_) {
    const auto snap = inst->stats.Get();
    msg::ComponentStats m;
    m.component_name(inst->name());
    m.process_name(options_.process);
    m.steps(snap.steps);
    m.step_mean_s(snap.mean_s);
    m.step_p99_s(snap.p99_s);
    m.step_max_s(snap.max_s);
    m.jitter_mean_s(snap.jitter_mean_s);
    m.jitter_max_s(snap.jitter_max_s);
    m.deadline_misses(snap.deadline_misses);
    out->Publish(m).IgnoreError();  // periodic: the next sample carries the same totals
  }
}

void Executor::BuildTopicList() { topics_ = GraphTopics(graph_, resolved_, options_.process); }

const TopicInfo* Executor::FindTopic(const std::string& name) const {
  for (const auto& t : topics_)
    if (t.name == name) return &t;
  return nullptr;
}

std::vector<Executor::Row> Executor::Report() const {
  std::vector<Row> rows;
  for (const auto& inst : instances_) rows.push_back({inst->name(), inst->stats.Get()});
  return rows;
}

}  // namespace dyad
