// dyad/component.hpp — the component API: everything a plugin author compiles against.
//
// A component is one node of an experiment graph: it declares typed inputs and outputs and
// parameters, and the runtime steps it either periodically (`rate_hz:` in the graph) or when a
// chosen input receives a sample (`trigger: <input>`). Components never talk to each other
// directly: every input and output is bound by the graph file to a DDS topic.
//
// Lifecycle (each call at most once, except Step):
//   construct -> Configure(ctx) -> Activate() -> Step(info)* -> Deactivate() -> Shutdown()
//   - Configure: read params, look up ports; the component is then "inactive". An error stops
//     the whole process before any component is activated.
//   - Activate: start talking to hardware, open files; then "active": Step() is called.
//   - Step: inputs have been polled just before; publish outputs. A non-OK Status stops the run
//     (all components are deactivated and shut down) and the process exits non-zero.
//   - Deactivate: stop motion, flush; back to "inactive". Called even after a failed Step().
//   - Shutdown: release everything. Called for every configured component.
// Threads: Configure, Activate, Deactivate and Shutdown run on the thread that runs the graph
// (components in graph order; Deactivate and Shutdown in reverse). Steps never overlap for one
// component: under the stepped clock they all run on that same thread; under the wall clock a
// periodic component steps on a thread of its own, and a triggered one on the thread that
// delivers its trigger sample (inside the publisher's Publish() for a publisher in this process,
// a DDS thread for a remote one). Every call happens-after the previous one (the runtime
// synchronises), so a component needs no locks for state only its lifecycle calls touch;
// serialized-subscription callbacks (below) are the exception: they run on delivering threads,
// concurrently with Step().
// Publishing from a component's own thread: Output<T>::Publish() may also be called outside
// Step(), from a thread the component owns (a server's handler, a device callback), between
// Activate() and Deactivate(), where it stops that thread (ports stay valid until Shutdown()
// returns, but once the run stops no triggered component steps on what is published). The
// transport's write is thread-safe; the port is not: calls on one Output must never overlap
// (Publish fills the sample's header and counts the sequence number without a lock), so
// serialise them, or give each thread its own output. Serialized callbacks of this process run
// on the publishing thread; so do the steps of triggered components under the wall clock (still
// never concurrently with themselves). Under the stepped clock such a sample is seen at
// whichever instant comes next: the run is no longer deterministic.
// Time: the timing the runtime reports for a component (`dyad/stats`, the table at exit) is the
// time of its own steps and callbacks; downstream work that runs inside its Publish() is not.
//
// Writing one (see components/examples/ for complete, tested ones):
//
//   class Doubler : public dyad::Component {
//    public:
//     static void Describe(dyad::ComponentSpec& spec) {
//       spec.Summary("Publishes twice the input value.");
//       spec.Param("factor", 2.0).Doc("multiplier");
//       spec.Input<dyad::msg::Counter>("in");
//       spec.Output<dyad::msg::Counter>("out");
//     }
//     dyad::Status Configure(dyad::Context& ctx) override {
//       factor_ = ctx.params().Double("factor");
//       in_ = &ctx.input<dyad::msg::Counter>("in");
//       out_ = &ctx.output<dyad::msg::Counter>("out");
//       return dyad::Status::OK();
//     }
//     dyad::Status Step(const dyad::StepInfo&) override {
//       for (const auto& s : in_->received()) {
//         dyad::msg::Counter c; c.value(static_cast<int64_t>(factor_ * s.value()));
//         if (auto st = out_->Publish(c); !st.ok()) return st;
//       }
//       return dyad::Status::OK();
//     }
//    private:
//     double factor_ = 2;
//     dyad::Input<dyad::msg::Counter>* in_ = nullptr;    // owned by the runtime
//     dyad::Output<dyad::msg::Counter>* out_ = nullptr;  // owned by the runtime
//   };
//   DYAD_PLUGIN(registry) { registry.Add<Doubler>("doubler"); }
//
// Build it as a shared library linking `dyad::runtime` (find_package(dyad)), put it where the
// graph's `plugins:` list or DYAD_PLUGIN_PATH points, and name `type: doubler` in a graph.
//
// Generic topics (ABI 2). Tools such as the recorder and replay handle topics they do not know at
// compile time. In Configure() they may ask the Context for:
//   - graph_topics(): every topic of the graph (port-bound, declared under `topics:` with a type,
//     and the runtime's `dyad/stats`), with its TypeInfo (IDL text, hash) and QoS;
//     graph_yaml() / graph_name(): the graph file as run (--set overrides applied); graph_folder():
//     what its relative paths are relative to; stepped(): the clock mode;
//     FindMessageType(name): any message type this process knows (IDL or short name).
//   - SubscribeSerialized(topic, callback): the callback receives every sample of the topic as CDR
//     bytes with its source stamp, receive time and sequence number. It runs on the delivering
//     thread (inside the publisher's Publish() for a publisher in this process, so delivery is
//     synchronous and deterministic under the stepped clock), from subscription until just before
//     Deactivate(); never concurrently for one subscription, concurrently across subscriptions.
//     The reader has KEEP_ALL history: nothing is dropped on the reader's side. It is RELIABLE
//     if the topic is, except when every writer is in this process (TopicInfo::writers_local):
//     intra-process delivery is synchronous, so reliability would only add protocol overhead
//     (2.7x the cost per sample, measured in bench/recorder). Keep the callback short (copy the
//     bytes, hand them to another thread).
//   - AdvertiseSerialized(topic, type): a writer that publishes CDR bytes of `type` on `topic`.
//   Both endpoints are owned by the runtime and live until Shutdown() returns.
//
// The plugin ABI's version and its history: kPluginAbiVersion below (the one place that says it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <dyad/message_traits.hpp>
#include <dyad/params.hpp>
#include <dyad/status.hpp>

namespace dyad {

// Bump when anything in this header changes layout or meaning; plugins built against another
// version are refused at load time with a message naming both versions.
// 1: typed ports only.
// 2: generic topics (above); the DDS source timestamp is the header's stamp.
// 3: ParamSpec::path (relative paths resolved against the graph file), Context::graph_folder().
// 4: input health (InputBase::writers_alive, writers_gone, deadline_misses).
// 5: ParamSpec::secret (redacted from Context::graph_yaml()).
// 6: live parameters: ParamSpec::live, Params::Set, Context::CheckLiveParam; a live param's value
//    in ctx.params() changes between steps.
// 7: TypeInfo::ros2_name (ROS 2 message types, no dyad Header: Publish stamps nothing in them).
// 8: Context::PrepareLiveParam (prepared off the step thread); a live param may be a Path().
inline constexpr uint32_t kPluginAbiVersion = 8;

// The runtime clock: wall time (ns since the Unix epoch) in `clock: wall` graphs, simulated time
// (ns since start) in `clock: stepped` graphs. Thread-safe.
class Clock {
 public:
  virtual ~Clock() = default;
  virtual int64_t now_ns() const = 0;
};

// Thread-safe; each line is prefixed with the component's name.
class Logger {
 public:
  enum class Level { kDebug, kInfo, kWarn, kError };
  virtual ~Logger() = default;
  virtual void Write(Level level, std::string_view message) = 0;
  void Debug(std::string_view m) { Write(Level::kDebug, m); }
  void Info(std::string_view m) { Write(Level::kInfo, m); }
  void Warn(std::string_view m) { Write(Level::kWarn, m); }
  void Error(std::string_view m) { Write(Level::kError, m); }
};

namespace detail {
// Implemented by the runtime's transport; ports forward to it. Not for component code.
class ReaderEndpoint {
 public:
  virtual ~ReaderEndpoint() = default;
  // Deserialises the next unread sample into *sample (a T); false when none is left.
  virtual bool TakeNext(void* sample) = 0;
  // Writers matched with this reader whose liveliness holds; -1 when the transport cannot tell.
  virtual int AliveWriters() const { return -1; }
  // Deadline periods (the topic's deadline_ms) that passed without a sample, so far.
  virtual uint64_t DeadlineMisses() const { return 0; }
};
class WriterEndpoint {
 public:
  virtual ~WriterEndpoint() = default;
  virtual Status Write(const void* sample) = 0;
  // Same, with the DDS source timestamp set to `stamp_ns` (the header's stamp) where supported.
  virtual Status WriteStamped(const void* sample, int64_t /*stamp_ns*/) { return Write(sample); }
};
}  // namespace detail

// An input port. The runtime polls it just before each Step(); between steps it does not change.
class InputBase {
 public:
  virtual ~InputBase() = default;
  const std::string& name() const { return name_; }
  const std::string& topic() const { return topic_; }  // empty when the graph leaves it unbound
  bool bound() const { return endpoint_ != nullptr; }
  // Clock time of the newest sample's arrival; -1 before the first.
  int64_t last_receive_ns() const { return last_receive_ns_; }
  // Samples received in the last poll.
  size_t new_count() const { return new_count_; }
  // Health of the writers on this input's topic, as of the last poll (docs/runtime.md, "Input
  // health"). writers_alive(): writers matched and alive; a writer whose process died, or whose
  // link is down, stops counting once the topic's `liveliness_ms` (else the network's `lease_s`)
  // has passed without word from it. -1: the transport cannot tell (in-memory tests). A
  // component can hold as soon as it drops to 0 instead of waiting out its own stale timeout;
  // writers_gone() says exactly that (there was a writer, and none is alive now).
  int writers_alive() const { return writers_alive_; }
  bool writers_gone() const { return had_writer_ && writers_alive_ == 0; }
  // Deadline misses so far: periods of the topic's `deadline_ms` that passed without a sample.
  uint64_t deadline_misses() const { return deadline_misses_; }

  // Runtime use only.
  void Bind(std::string name, std::string topic, detail::ReaderEndpoint* endpoint) {
    name_ = std::move(name); topic_ = std::move(topic); endpoint_ = endpoint;
  }
  virtual size_t Poll(int64_t now_ns) = 0;

 protected:
  std::string name_, topic_;
  detail::ReaderEndpoint* endpoint_ = nullptr;  // owned by the runtime; null when unbound
  int64_t last_receive_ns_ = -1;
  size_t new_count_ = 0;
  int writers_alive_ = -1;
  bool had_writer_ = false;
  uint64_t deadline_misses_ = 0;
  void PollHealth() {
    writers_alive_ = endpoint_->AliveWriters();
    had_writer_ = had_writer_ || writers_alive_ > 0;
    deadline_misses_ = endpoint_->DeadlineMisses();
  }
};

template <class T>
class Input final : public InputBase {
 public:
  // Samples received since the previous step, oldest first (at most the topic's history depth).
  const std::vector<T>& received() const { return received_; }
  // The newest sample ever received; nullptr before the first.
  const T* latest() const {
    if (!received_.empty()) return &received_.back();
    return previous_.empty() ? nullptr : &previous_.back();
  }

  // Takes each sample into an object of an earlier poll, so its strings and sequences keep their
  // storage: once they have grown to the samples' sizes a poll allocates nothing and moves
  // nothing. previous_ holds the last poll that received anything (latest()); objects no poll
  // holds wait in spare_.
  size_t Poll(int64_t now_ns) override {
    new_count_ = 0;
    if (endpoint_ == nullptr) return 0;
    PollHealth();
    if (!received_.empty()) std::swap(received_, previous_);  // received_: previous_'s old objects
    size_t n = 0;
    while (n < received_.size() && endpoint_->TakeNext(&received_[n])) ++n;
    if (n < received_.size()) {
      for (size_t i = n; i < received_.size(); ++i) spare_.push_back(std::move(received_[i]));
      received_.erase(received_.begin() + static_cast<std::ptrdiff_t>(n), received_.end());
    } else {
      for (;;) {
        if (spare_.empty()) spare_.emplace_back();
        if (!endpoint_->TakeNext(&spare_.back())) break;
        received_.push_back(std::move(spare_.back()));
        spare_.pop_back();
      }
    }
    new_count_ = received_.size();
    if (new_count_ > 0) last_receive_ns_ = now_ns;
    return new_count_;
  }

 private:
  std::vector<T> received_, previous_, spare_;
};

class OutputBase {
 public:
  virtual ~OutputBase() = default;
  const std::string& name() const { return name_; }
  const std::string& topic() const { return topic_; }
  bool bound() const { return endpoint_ != nullptr; }
  uint64_t published() const { return sequence_; }

  // Runtime use only.
  void Bind(std::string name, std::string topic, std::string source, detail::WriterEndpoint* endpoint,
            const Clock* clock) {
    name_ = std::move(name); topic_ = std::move(topic); source_ = std::move(source);
    endpoint_ = endpoint; clock_ = clock;
  }

 protected:
  std::string name_, topic_, source_;
  detail::WriterEndpoint* endpoint_ = nullptr;  // owned by the runtime; null when unbound
  const Clock* clock_ = nullptr;                // owned by the runtime
  uint64_t sequence_ = 0;
};

template <class T>
class Output final : public OutputBase {
 public:
  // Fills sample.header() (source, next sequence number, clock stamp) and publishes it; a ROS 2
  // type's header is the component's to fill (message_traits.hpp). Unbound outputs accept and
  // drop samples.
  Status Publish(T& sample) {
    const int64_t now = clock_ ? clock_->now_ns() : 0;
    ++sequence_;
    if constexpr (MessageTraits<T>::kDyadHeader) {
      auto& h = sample.header();
      if (h.source() != source_) h.source(source_);  // a reused sample has it: no copy
      h.sequence_number(sequence_);
      h.stamp_ns(now);
    }
    if (endpoint_ == nullptr) return Status::OK();
    return endpoint_->WriteStamped(&sample, now);
  }
};

// A port as declared by Describe().
struct PortSpec {
  std::string name;
  const TypeInfo* type = nullptr;  // static storage
  std::string doc;
  bool optional = false;  // may be left unbound in the graph (an output: without a warning)
  std::function<std::unique_ptr<InputBase>()> make_input;
  std::function<std::unique_ptr<OutputBase>()> make_output;

  PortSpec& Doc(std::string d) { doc = std::move(d); return *this; }
  PortSpec& Optional() { optional = true; return *this; }
};

// What a component type declares about itself: filled by its static Describe(spec).
class ComponentSpec {
 public:
  ComponentSpec& Summary(std::string s) { summary_ = std::move(s); return *this; }

  // A parameter with a default; its type follows the default's C++ type.
  ParamSpec& Param(std::string name, double default_value) { return AddParam(std::move(name), ParamType::kDouble, default_value); }
  ParamSpec& Param(std::string name, int default_value) { return AddParam(std::move(name), ParamType::kInt, int64_t{default_value}); }
  ParamSpec& Param(std::string name, int64_t default_value) { return AddParam(std::move(name), ParamType::kInt, default_value); }
  ParamSpec& Param(std::string name, bool default_value) { return AddParam(std::move(name), ParamType::kBool, default_value); }
  ParamSpec& Param(std::string name, const char* default_value) { return AddParam(std::move(name), ParamType::kString, std::string(default_value)); }
  ParamSpec& Param(std::string name, std::string default_value) { return AddParam(std::move(name), ParamType::kString, std::move(default_value)); }
  ParamSpec& Param(std::string name, std::vector<double> default_value) { return AddParam(std::move(name), ParamType::kDoubleList, std::move(default_value)); }
  ParamSpec& Param(std::string name, std::vector<std::string> default_value) { return AddParam(std::move(name), ParamType::kStringList, std::move(default_value)); }
  // A parameter the graph must set.
  ParamSpec& RequiredParam(std::string name, ParamType type);
  // A kYaml parameter (structured values the component parses itself); default is YAML text.
  ParamSpec& YamlParam(std::string name, std::string default_yaml);

  template <class T>
  PortSpec& Input(std::string name) {
    PortSpec& p = AddPort(inputs_, std::move(name), &TypeInfoOf<T>());
    p.make_input = [] { return std::unique_ptr<InputBase>(new dyad::Input<T>()); };
    return p;
  }
  template <class T>
  PortSpec& Output(std::string name) {
    PortSpec& p = AddPort(outputs_, std::move(name), &TypeInfoOf<T>());
    p.make_output = [] { return std::unique_ptr<OutputBase>(new dyad::Output<T>()); };
    return p;
  }

  const std::string& summary() const { return summary_; }
  const std::vector<ParamSpec>& params() const { return params_; }
  const std::vector<PortSpec>& inputs() const { return inputs_; }
  const std::vector<PortSpec>& outputs() const { return outputs_; }
  const ParamSpec* FindParam(std::string_view name) const;
  const PortSpec* FindInput(std::string_view name) const;
  const PortSpec* FindOutput(std::string_view name) const;

 private:
  ParamSpec& AddParam(std::string name, ParamType type, std::optional<ParamValue> default_value);
  PortSpec& AddPort(std::vector<PortSpec>& ports, std::string name, const TypeInfo* type);
  std::string summary_;
  std::vector<ParamSpec> params_;
  std::vector<PortSpec> inputs_, outputs_;
};

// A topic of the graph as the runtime wires it (Context::graph_topics()).
struct TopicInfo {
  std::string name;
  const TypeInfo* type = nullptr;  // static storage
  bool reliable = true;            // RELIABLE, else BEST_EFFORT
  int depth = 1;                   // KEEP_LAST depth of the graph's ports on this topic
  double deadline_ms = 0;          // 0: none
  // "component.port" of every output bound to it in the graph (any process); "runtime" for
  // dyad/stats; empty for a topic only declared under `topics:` (published from outside).
  std::vector<std::string> writers;
  // Every writer the graph knows is in this process (at least one): delivery is intra-process.
  bool writers_local = false;
};

// One sample delivered by a serialized subscription. `cdr` is valid during the callback only.
struct SerializedSample {
  std::span<const uint8_t> cdr;  // CDR with its 4-byte encapsulation header, as on the wire
  int64_t source_stamp_ns = 0;   // DDS source timestamp: for dyad writers the header's stamp
                                 // (writer's runtime clock: Unix ns under wall, sim ns under stepped)
  int64_t receive_ns = 0;        // this runtime's clock at delivery (same clock kinds)
  uint64_t sequence = 0;         // DDS sequence number within its writer: 1, 2, ... (= header's)
};
using SerializedCallback = std::function<void(const SerializedSample&)>;

// Publishes CDR bytes of one type on one topic (Context::AdvertiseSerialized). Owned by the runtime.
class SerializedWriter {
 public:
  virtual ~SerializedWriter() = default;
  virtual const std::string& topic() const = 0;
  virtual const TypeInfo& type() const = 0;
  // Publishes one sample given as CDR with its encapsulation header (e.g. as recorded). The DDS
  // source timestamp is `source_stamp_ns`, or the runtime clock's now when it is negative. The
  // bytes are published as they are: the header inside keeps its source, sequence and stamp.
  // Fails: InvalidArgument when the bytes do not decode as the type, IOError when DDS refuses.
  virtual Status Write(std::span<const uint8_t> cdr, int64_t source_stamp_ns = -1) = 0;
  virtual uint64_t written() const = 0;
};

// What the runtime hands a component in Configure(). Valid until Shutdown() returns.
class Context {
 public:
  virtual ~Context() = default;
  virtual const std::string& name() const = 0;      // instance name in the graph
  virtual const Params& params() const = 0;         // validated, defaults filled
  virtual const Clock& clock() const = 0;
  virtual Logger& log() = 0;
  // The graph's seed mixed with the instance name: same graph + seed = same value.
  virtual uint64_t seed() const = 0;
  // Nominal period; 0 for triggered components.
  virtual int64_t period_ns() const = 0;
  // Ends the run cleanly after the current step (e.g. a replay reached its end).
  virtual void RequestStop(std::string reason) = 0;

  // Generic topics (see the file comment). Call these in Configure() only. The runtime implements
  // them all; the defaults (empty graph, Unimplemented) serve test fakes of Context.
  virtual const std::string& graph_name() const;
  virtual const std::string& graph_yaml() const;  // the graph file as run (Graph::yaml_text)
  // The absolute folder the graph's relative paths are relative to (its file's; ABI 3).
  virtual const std::string& graph_folder() const;
  virtual bool stepped() const { return false; }  // `clock: stepped`
  // Every topic of the graph, sorted by name, `dyad/stats` included.
  virtual const std::vector<TopicInfo>& graph_topics() const;
  // A message type known in this process, by IDL name ("dyad::msg::Counter") or short name; null if none.
  virtual const TypeInfo* FindMessageType(std::string_view /*name*/) const { return nullptr; }
  // Calls `callback` for every sample of `topic` (a graph topic) from now until just before
  // Deactivate(). Fails: NotFound (not a graph topic), Internal (DDS), FailedPrecondition (after Configure).
  virtual Status SubscribeSerialized(const std::string& topic, SerializedCallback callback);
  // A writer of `type` on `topic`, with the topic's graph QoS (defaults if not a graph topic).
  // Fails: InvalidArgument (the topic carries another type in this process), Internal (DDS).
  virtual StatusOr<SerializedWriter*> AdvertiseSerialized(const std::string& topic, const TypeInfo& type);

  // Live parameters (params.hpp; ABI 6). In Configure(): a check of new values of the live param
  // `name` that its declaration cannot express (e.g. a list as long as the model has layers). The
  // runtime runs it on the step thread at the step boundary, after the declaration's checks and
  // before the value takes effect; an error refuses the change with its message, and the old
  // value stays. The default (test fakes of Context) keeps no check.
  using LiveParamCheck = std::function<Status(const ParamValue& value)>;
  virtual void CheckLiveParam(const std::string& /*name*/, LiveParamCheck /*check*/) {}
  // Live parameters (ABI 8). In Configure(): for a live param whose check takes longer than a
  // step allows, typically preparing what the value names (load and check a model file, build
  // what Step() will use). `prepare` runs, on the wall clock, on a runtime thread while the
  // component keeps stepping; under the stepped clock at the step boundary (a run is
  // reproducible). It may read ctx.params(): none of the component's live params changes while it
  // runs (its later requests wait, answered in order). It must not throw (a throw refuses the
  // value, saying so). Once it returned OK, the first step boundary applies the value (the answer
  // carries that step) and calls `commit` there, on the step thread, before the next Step() (also
  // when the value equals the old one): where the component switches to what `prepare` made. An
  // error of `prepare` refuses the value with its message; a run that stops before the boundary
  // refuses it too, without `commit`. What `prepare` shares with Step() is the component's to guard.
  using LiveParamPrepare = std::function<Status(const ParamValue& value)>;
  using LiveParamCommit = std::function<void(const ParamValue& value)>;
  virtual void PrepareLiveParam(const std::string& /*name*/, LiveParamPrepare /*prepare*/, LiveParamCommit /*commit*/) {}

  // The port declared under `name` with type T. Asking for an undeclared port or another type is
  // a programming error: it aborts naming the component and port.
  template <class T>
  dyad::Input<T>& input(std::string_view name) { return *static_cast<dyad::Input<T>*>(FindInput(name, TypeInfoOf<T>())); }
  template <class T>
  dyad::Output<T>& output(std::string_view name) { return *static_cast<dyad::Output<T>*>(FindOutput(name, TypeInfoOf<T>())); }

 protected:
  virtual InputBase* FindInput(std::string_view name, const TypeInfo& type) = 0;
  virtual OutputBase* FindOutput(std::string_view name, const TypeInfo& type) = 0;
};

struct StepInfo {
  int64_t now_ns = 0;        // clock time at the start of this step
  uint64_t index = 0;        // 0, 1, 2, ...
  int64_t period_ns = 0;     // nominal; 0 when triggered
};

// Base class of every component. Non-copyable; the runtime owns instances.
class Component {
 public:
  Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;
  virtual ~Component() = default;

  virtual Status Configure(Context& ctx) = 0;
  virtual Status Activate() { return Status::OK(); }
  virtual Status Step(const StepInfo& info) = 0;
  virtual Status Deactivate() { return Status::OK(); }
  virtual void Shutdown() {}
};

// One component type: its registered name, its self-description and its factory.
struct ComponentType {
  std::string name;
  void (*describe)(ComponentSpec&) = nullptr;
  std::unique_ptr<Component> (*create)() = nullptr;
  std::string plugin_path;  // filled by the loader
};

// Handed to a plugin's DYAD_PLUGIN body.
class PluginRegistry {
 public:
  virtual ~PluginRegistry() = default;
  virtual void AddType(ComponentType type) = 0;

  // C must be default-constructible and have `static void Describe(ComponentSpec&)`.
  template <class C>
  void Add(std::string type_name) {
    ComponentType t;
    t.name = std::move(type_name);
    t.describe = &C::Describe;
    t.create = [] { return std::unique_ptr<Component>(new C()); };
    AddType(std::move(t));
  }
};

}  // namespace dyad

// A plugin's one entry point: `DYAD_PLUGIN(registry) { registry.Add<MyComponent>("my_type"); }`.
#define DYAD_PLUGIN(REGISTRY)                                                             \
  extern "C" __attribute__((visibility("default"))) uint32_t dyad_plugin_abi_version() { \
    return ::dyad::kPluginAbiVersion;                                                     \
  }                                                                                       \
  extern "C" __attribute__((visibility("default"))) void dyad_plugin_register(            \
      ::dyad::PluginRegistry& REGISTRY)
