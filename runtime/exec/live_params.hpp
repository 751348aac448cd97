// LiveParams — the live parameters of one process's components (dyad/params.hpp, "Live
// parameters"; docs/runtime.md). It reads dyad/param_requests, keeps each request for this
// graph's components that run here until that component's next step boundary, and there (on the
// component's step thread, just before its Step) validates it against the parameter's
// declaration and the component's own check (Context::CheckLiveParam), applies it to the
// component's Params, and answers on dyad/params: applied (old and new value), refused (why) or
// the value asked for. Requests for components of other processes are theirs to answer.
//
// In a stepped run the requests come from inside the process (a param_script's output), are
// delivered as they are written, and are taken at the next step boundary of their component: the
// same run gives the same changes at the same steps.
//
// Prepared params (Context::PrepareLiveParam: a check that takes longer than a step, such as
// loading a model): on the wall clock a set that passed the quick checks goes to one preparer
// thread; the step thread carries on, and the first step boundary after the preparation ended
// applies it and calls the component's commit, or refuses it (answered then, with that step).
// Requests for the same component that came after it wait for it, so each component's requests
// are answered in the order they came. Under the stepped clock the preparation runs at the
// boundary itself: a run is reproducible. Stop() answers whatever is left: nothing goes unanswered.
//
// Threads: BeforeStep(i) runs on target i's step thread (several targets, several threads);
// the request reader's callback only raises a flag. Cost when nothing is asked: three atomic
// loads. While a request waits behind a preparation, every target's boundary takes the mutex.
// Lock discipline: what mutex_ and publish_mutex_ guard is declared with GUARDED_BY (clang checks
// it, dyad/thread_annotations.hpp).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/thread_annotations.hpp>

#include "dds/transport.hpp"

namespace dyad {

class LiveParams {
 public:
  struct Target {
    std::string component;
    const ComponentSpec* spec = nullptr;
    Params* params = nullptr;           // the component's (its ctx.params())
    const uint64_t* steps = nullptr;    // its steps so far
    Logger* log = nullptr;
    std::map<std::string, Context::LiveParamCheck> checks;    // CheckLiveParam()
    struct Prepared {
      Context::LiveParamPrepare prepare;
      Context::LiveParamCommit commit;
    };
    std::map<std::string, Prepared> prepares;  // PrepareLiveParam()
  };

  LiveParams() = default;
  LiveParams(const LiveParams&) = delete;
  LiveParams& operator=(const LiveParams&) = delete;
  ~LiveParams() { Stop(); }

  // Opens the request reader and the answer writer on `transport`; answers are stamped by
  // `clock` and sourced "dyad/<process>". Relative live paths resolve against `graph_folder`.
  // `stepped`: preparations run at the step boundary (above).
  Status Open(Transport* transport, const std::string& graph_name, const std::string& process, const Clock* clock,
              const std::string& graph_folder, bool stepped, std::vector<Target*> targets) EXCLUDES(mutex_, publish_mutex_);
  // At a step boundary of targets[index], on its step thread.
  void BeforeStep(size_t index) {
    if (!arrived_.load(std::memory_order_acquire) && queued_.load(std::memory_order_acquire) == 0 &&
        prepared_.load(std::memory_order_acquire) == 0)
      return;
    Apply(index);
  }
  // When the steps have ended, before the components deactivate: waits for a preparation under
  // way (one at most is started), refuses the sets not applied ("the run stopped ...") and
  // answers the gets still waiting, so no request goes unanswered. Idempotent; REQUIRES the
  // transport alive the first time.
  void Stop() EXCLUDES(mutex_, publish_mutex_);

 private:
  // A set being prepared for one target: it passed the quick checks; `result` once done. While
  // kRunning only the preparer thread touches it.
  struct Preparation {
    enum class State { kNone, kRunning, kDone } state = State::kNone;
    msg::ParamChange request;
    ParamValue value;
    Status result;
  };

  void Apply(size_t index) EXCLUDES(mutex_);
  void Take() REQUIRES(mutex_);
  // The answer to `request`, or nullopt when it passed the quick checks of a prepared param:
  // then `*prepare` holds it, to be prepared and then Finish()ed.
  std::optional<msg::ParamChange> Answer(Target& target, const msg::ParamChange& request, Preparation* prepare);
  msg::ParamChange ApplyOrRefuse(Target& target, const Preparation& p);
  msg::ParamChange Refused(Target& target, msg::ParamChange answer, const std::string& why);
  void RunPreparations() EXCLUDES(mutex_);  // the preparer thread
  void Publish(msg::ParamChange answer) EXCLUDES(publish_mutex_);

  std::string graph_name_;
  std::vector<Target*> targets_;
  // Both set by Open; the reader is owned by the transport.
  TypedReader* reader_ PT_GUARDED_BY(mutex_) = nullptr;
  std::unique_ptr<Output<msg::ParamChange>> answers_ PT_GUARDED_BY(publish_mutex_);
  std::atomic<bool> arrived_{false};
  std::atomic<int> queued_{0};
  Mutex mutex_;  // the reader, the queues, the preparations and the preparer's state
  std::vector<std::deque<msg::ParamChange>> queues_ GUARDED_BY(mutex_);
  std::string graph_folder_;
  bool stepped_ = false;
  // Preparations (prepared_: how many are done and not yet applied).
  std::vector<Preparation> preparations_ GUARDED_BY(mutex_);
  std::atomic<int> prepared_{0};
  std::deque<size_t> to_prepare_ GUARDED_BY(mutex_);  // target indices
  bool stopping_ GUARDED_BY(mutex_) = false;
  bool stopped_ GUARDED_BY(mutex_) = false;
  std::condition_variable prepare_cv_;
  std::thread preparer_;  // started by the first preparation
  Mutex publish_mutex_;   // answers_ (its sequence numbers)
};

}  // namespace dyad
