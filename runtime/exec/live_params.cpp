#include "exec/live_params.hpp"

#include <yaml-cpp/yaml.h>

#include <exception>

#include "dyad/join_list.hpp"
#include "dyad/validate.hpp"
#include "graph/runtime_topics.hpp"

namespace dyad {

Status LiveParams::Open(Transport* transport, const std::string& graph_name, const std::string& process, const Clock* clock,
                        const std::string& graph_folder, bool stepped, std::vector<Target*> targets) {
  graph_name_ = graph_name;
  graph_folder_ = graph_folder;
  stepped_ = stepped;
  targets_ = std::move(targets);
  {
    MutexLock lock(mutex_);  // no other thread yet: for the analysis
    queues_.resize(targets_.size());
    preparations_.resize(targets_.size());
  }
  auto r = CreateRuntimeReader(transport, runtime_topics::kParamRequests,
                               [this] { arrived_.store(true, std::memory_order_release); });
  if (!r.ok()) return r.status();
  reader_ = r.value();
  auto w = CreateRuntimeWriter(transport, runtime_topics::kParams);
  if (!w.ok()) return w.status();
  MutexLock lock(publish_mutex_);
  answers_ = std::make_unique<Output<msg::ParamChange>>();
  answers_->Bind("params", runtime_topics::kParams.name, "dyad/" + process, w.value(), clock);
  return Status::OK();
}

// Moves every waiting request for one of this process's components into its queue.
void LiveParams::Take() {
  arrived_.store(false, std::memory_order_release);  // before taking: a sample arriving now raises it again
  msg::ParamChange request;
  while (reader_->TakeNext(&request)) {
    if (request.graph_name() != graph_name_ || (request.op() != "set" && request.op() != "get")) continue;
    for (size_t i = 0; i < targets_.size(); ++i)
      if (targets_[i]->component == request.component_name()) {
        queues_[i].push_back(request);
        queued_.fetch_add(1, std::memory_order_release);
      }
  }
}

namespace {
// Runs a component's preparation; a throw refuses the value instead of ending the process.
Status RunPrepare(const Context::LiveParamPrepare& prepare, const ParamValue& value) {
  try {
    return prepare(value);
  } catch (const std::exception& e) {
    return Status::Internal(std::string("the preparation threw: ") + e.what());
  } catch (...) {
    return Status::Internal("the preparation threw");
  }
}
}  // namespace

void LiveParams::Apply(size_t index) {
  Target& target = *targets_[index];
  std::optional<Preparation> done;
  std::deque<msg::ParamChange> mine;
  {
    MutexLock lock(mutex_);
    Take();
    Preparation& preparation = preparations_[index];
    if (preparation.state == Preparation::State::kRunning) return;  // the requests after it wait
    if (preparation.state == Preparation::State::kDone) {
      done = std::move(preparation);
      preparation = {};
      prepared_.fetch_sub(1, std::memory_order_release);
    }
    mine.swap(queues_[index]);
    queued_.fetch_sub(static_cast<int>(mine.size()), std::memory_order_release);
  }
  if (done) Publish(ApplyOrRefuse(target, *done));  // commits first: the requests below see it
  while (!mine.empty()) {
    const msg::ParamChange request = std::move(mine.front());
    mine.pop_front();
    Preparation p;
    if (std::optional<msg::ParamChange> answer = Answer(target, request, &p)) {
      Publish(std::move(*answer));
      continue;
    }
    if (stepped_) {  // at the boundary: the same step in every run
      p.result = RunPrepare(target.prepares.at(request.param_name()).prepare, p.value);
      Publish(ApplyOrRefuse(target, p));
      continue;
    }
    MutexLock lock(mutex_);
    queued_.fetch_add(static_cast<int>(mine.size()), std::memory_order_release);
    queues_[index].insert(queues_[index].begin(), std::make_move_iterator(mine.begin()), std::make_move_iterator(mine.end()));
    p.state = Preparation::State::kRunning;
    preparations_[index] = std::move(p);
    to_prepare_.push_back(index);
    if (!preparer_.joinable()) preparer_ = std::thread([this] { RunPreparations(); });
    prepare_cv_.notify_one();
    return;
  }
}

void LiveParams::RunPreparations() {
  UniqueLock lock(mutex_);
  for (;;) {
    prepare_cv_.wait(lock.native(), [this] {
      mutex_.AssertHeld();  // the wait calls its predicate with the lock held
      return stopping_ || !to_prepare_.empty();
    });
    if (stopping_) return;  // Stop() refuses what was not prepared
    const size_t index = to_prepare_.front();
    to_prepare_.pop_front();
    Preparation& p = preparations_[index];  // kRunning: this thread's until marked done
    const Context::LiveParamPrepare& prepare = targets_[index]->prepares.at(p.request.param_name()).prepare;
    lock.Unlock();
    Status result = RunPrepare(prepare, p.value);
    lock.Lock();
    p.result = std::move(result);
    p.state = Preparation::State::kDone;
    prepared_.fetch_add(1, std::memory_order_release);
  }
}

void LiveParams::Stop() {
  {
    MutexLock lock(mutex_);
    if (stopped_) return;
    stopped_ = stopping_ = true;
  }
  prepare_cv_.notify_all();
  if (preparer_.joinable()) preparer_.join();
  if (!answers_ || reader_ == nullptr) return;  // never opened
  std::vector<msg::ParamChange> answers;
  const std::string why = "the run stopped before the change took effect";
  {
    MutexLock lock(mutex_);
    Take();
    for (size_t i = 0; i < targets_.size(); ++i) {
      if (preparations_[i].state != Preparation::State::kNone) answers.push_back(Refused(*targets_[i], preparations_[i].request, why));
      preparations_[i] = {};
      for (const msg::ParamChange& request : queues_[i]) {
        Preparation unused;
        std::optional<msg::ParamChange> get = request.op() == "get" ? Answer(*targets_[i], request, &unused) : std::nullopt;
        answers.push_back(get ? *get : Refused(*targets_[i], request, why));
      }
      queues_[i].clear();
    }
    queued_.store(0, std::memory_order_release);
    prepared_.store(0, std::memory_order_release);
  }
  for (auto& a : answers) Publish(std::move(a));
}

msg::ParamChange LiveParams::Refused(Target& target, msg::ParamChange a, const std::string& why) {
  a.step(*target.steps);
  a.old_value("");
  a.op("refused");
  a.reason(why);
  target.log->Warn("param " + a.param_name() + " = " + a.value() + " (" + a.who() + "): refused: " + why);
  return a;
}

std::optional<msg::ParamChange> LiveParams::Answer(Target& target, const msg::ParamChange& request, Preparation* prepare) {
  const ParamSpec* spec = target.spec->FindParam(request.param_name());
  std::vector<std::string> live;
  for (const auto& p : target.spec->params())
    if (p.live) live.push_back(p.name);
  if (spec == nullptr)
    return Refused(target, request, "no parameter '" + request.param_name() + "' (live: " + (live.empty() ? "none" : JoinList(live)) + ")");
  if (!spec->live)
    return Refused(target, request,
                   "'" + request.param_name() + "' is not live: read once, at configure (live: " + (live.empty() ? "none" : JoinList(live)) + ")");
  if (request.op() == "get") {
    msg::ParamChange a = request;
    a.step(*target.steps);
    a.old_value("");
    a.reason("");
    a.op("value");
    a.value(ToYamlText(target.params->values().at(request.param_name())));
    return a;
  }
  YAML::Node node;
  try {
    node = YAML::Load(request.value());
  } catch (const YAML::Exception& e) {
    return Refused(target, request, "not YAML: " + std::string(e.what()));
  }
  StatusOr<ParamValue> value = ParamFromYaml(*spec, node);
  if (!value.ok()) return Refused(target, request, value.status().message());
  if (spec->path) ResolvePaths(graph_folder_, &value.value());
  if (auto check = target.checks.find(request.param_name()); check != target.checks.end())
    if (Status s = check->second(*value); !s.ok()) return Refused(target, request, s.message());
  Preparation p;
  p.request = request;
  p.value = std::move(value).value();
  if (target.prepares.count(request.param_name())) {
    *prepare = std::move(p);
    return std::nullopt;
  }
  return ApplyOrRefuse(target, p);
}

// At this step boundary, on the target's step thread: applies a set that passed every check and
// its preparation (then the component's commit), or refuses it with the preparation's error.
msg::ParamChange LiveParams::ApplyOrRefuse(Target& target, const Preparation& p) {
  if (!p.result.ok()) return Refused(target, p.request, p.result.message());
  msg::ParamChange a = p.request;
  const std::string old = ToYamlText(target.params->values().at(p.request.param_name()));
  a.step(*target.steps);
  a.reason("");
  a.op("applied");
  a.old_value(old);
  a.value(ToYamlText(p.value));
  target.params->Set(p.request.param_name(), p.value);
  if (auto prepared = target.prepares.find(p.request.param_name()); prepared != target.prepares.end() && prepared->second.commit)
    prepared->second.commit(p.value);
  target.log->Info("param " + p.request.param_name() + ": " + old + " -> " + a.value() + " (" + p.request.who() + ")");
  return a;
}

void LiveParams::Publish(msg::ParamChange answer) {
  MutexLock lock(publish_mutex_);
  answers_->Publish(answer).IgnoreError();  // the log has said it too
}

}  // namespace dyad
