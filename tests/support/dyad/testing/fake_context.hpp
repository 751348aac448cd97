// A Context for component unit tests, without DDS: params from the component's Describe()
// defaults plus overrides, outputs that keep every published sample, inputs fed by the test.
// Shared by the component tests (human_input, observer, deliberator).
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <dyad/component.hpp>

namespace dyad::testing {

template <class T>
class CapturingWriter final : public detail::WriterEndpoint {
 public:
  Status Write(const void* sample) override {
    samples.push_back(*static_cast<const T*>(sample));
    return Status::OK();
  }
  std::vector<T> samples;
};

template <class T>
class QueueReader final : public detail::ReaderEndpoint {
 public:
  bool TakeNext(void* sample) override {
    if (queue.empty()) return false;
    *static_cast<T*>(sample) = queue.front();
    queue.pop_front();
    return true;
  }
  std::deque<T> queue;
};

class FakeClock final : public Clock {
 public:
  int64_t now_ns() const override { return now; }
  int64_t now = 0;
};

class NullLogger final : public Logger {
 public:
  void Write(Level, std::string_view m) override { lines.emplace_back(m); }
  std::vector<std::string> lines;
};

class FakeContext final : public Context {
 public:
  // `describe` is the component's Describe; `overrides` replace defaults (required params too).
  FakeContext(void (*describe)(ComponentSpec&), std::map<std::string, ParamValue> overrides, uint64_t seed = 42)
      : seed_(seed) {
    describe(spec_);
    std::map<std::string, ParamValue> values;
    for (const ParamSpec& p : spec_.params())
      if (p.default_value) values[p.name] = *p.default_value;
    for (auto& [k, v] : overrides) values[k] = v;
    params_ = Params(std::move(values));
    for (const PortSpec& p : spec_.inputs()) inputs_[p.name] = p.make_input();
    for (const PortSpec& p : spec_.outputs()) {
      outputs_[p.name] = p.make_output();
    }
  }

  // Binds output `name` to a capturing writer and returns it.
  template <class T>
  CapturingWriter<T>& Capture(const std::string& name) {
    auto w = std::make_unique<CapturingWriter<T>>();
    auto* raw = w.get();
    outputs_.at(name)->Bind(name, name, "test", raw, &clock_);
    writers_.push_back(std::move(w));
    return *raw;
  }
  // Binds input `name` to a queue the test fills; call Poll(now) before each Step.
  template <class T>
  QueueReader<T>& Feed(const std::string& name) {
    auto r = std::make_unique<QueueReader<T>>();
    auto* raw = r.get();
    inputs_.at(name)->Bind(name, name, raw);
    readers_.push_back(std::move(r));
    return *raw;
  }
  void PollInputs() {
    for (auto& [n, in] : inputs_) in->Poll(clock_.now);
  }

  const std::string& name() const override { return name_; }
  const Params& params() const override { return params_; }
  const Clock& clock() const override { return clock_; }
  Logger& log() override { return log_; }
  uint64_t seed() const override { return seed_; }
  int64_t period_ns() const override { return 100'000'000; }
  void RequestStop(std::string reason) override { stop_reason = std::move(reason); }
  bool stepped() const override { return stepped_clock; }

  // Live parameters as the runtime applies them at a step boundary: the component's check, its
  // prepare (here on the calling thread), the new value, then its commit. Returns the refusal.
  void CheckLiveParam(const std::string& name, LiveParamCheck check) override { checks_[name] = std::move(check); }
  void PrepareLiveParam(const std::string& name, LiveParamPrepare prepare, LiveParamCommit commit) override {
    prepares_[name] = {std::move(prepare), std::move(commit)};
  }
  Status SetLive(const std::string& name, const ParamValue& value) {
    if (auto c = checks_.find(name); c != checks_.end())
      if (Status s = c->second(value); !s.ok()) return s;
    auto p = prepares_.find(name);
    if (p != prepares_.end())
      if (Status s = p->second.first(value); !s.ok()) return s;
    params_.Set(name, value);
    if (p != prepares_.end()) p->second.second(value);
    return Status::OK();
  }
  // Serialized subscriptions: kept per topic; Deliver() hands them a sample's CDR bytes.
  Status SubscribeSerialized(const std::string& topic, SerializedCallback callback) override {
    subscriptions_[topic].push_back(std::move(callback));
    return Status::OK();
  }
  void Deliver(const std::string& topic, std::span<const uint8_t> cdr) {
    SerializedSample sample;
    sample.cdr = cdr;
    sample.receive_ns = clock_.now;
    for (auto& callback : subscriptions_[topic]) callback(sample);
  }
  void set_graph_yaml(std::string yaml) { graph_yaml_ = std::move(yaml); }
  const std::string& graph_yaml() const override { return graph_yaml_; }

  std::string stop_reason;
  bool stepped_clock = false;
  FakeClock clock_;
  NullLogger log_;

 protected:
  InputBase* FindInput(std::string_view name, const TypeInfo&) override { return inputs_.at(std::string(name)).get(); }
  OutputBase* FindOutput(std::string_view name, const TypeInfo&) override { return outputs_.at(std::string(name)).get(); }

 private:
  std::string name_ = "under_test";
  uint64_t seed_;
  ComponentSpec spec_;
  Params params_;
  std::map<std::string, std::unique_ptr<InputBase>> inputs_;
  std::map<std::string, std::unique_ptr<OutputBase>> outputs_;
  std::vector<std::unique_ptr<detail::WriterEndpoint>> writers_;
  std::vector<std::unique_ptr<detail::ReaderEndpoint>> readers_;
  std::map<std::string, LiveParamCheck> checks_;
  std::map<std::string, std::pair<LiveParamPrepare, LiveParamCommit>> prepares_;
  std::string graph_yaml_;
  std::map<std::string, std::vector<SerializedCallback>> subscriptions_;
};

}  // namespace dyad::testing
