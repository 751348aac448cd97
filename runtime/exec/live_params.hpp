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
// Threads: BeforeStep(i) runs on target i's step thread (several targets, several threads);
// the request reader's callback only raises a flag. Cost when nothing is asked: two atomic loads.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

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
    std::map<std::string, Context::LiveParamCheck> checks;  // CheckLiveParam()
  };

  // Opens the request reader and the answer writer on `transport`; answers are stamped by
  // `clock` and sourced "dyad/<process>".
  Status Open(Transport* transport, const std::string& graph_name, const std::string& process, const Clock* clock,
              std::vector<Target*> targets);
  // At a step boundary of targets[index], on its step thread.
  void BeforeStep(size_t index) {
    if (!arrived_.load(std::memory_order_acquire) && queued_.load(std::memory_order_acquire) == 0) return;
    Apply(index);
  }

 private:
  void Apply(size_t index);
  void Take();  // REQUIRES: mutex_ held
  msg::ParamChange Answer(Target& target, const msg::ParamChange& request);
  void Publish(msg::ParamChange answer);

  std::string graph_name_;
  std::vector<Target*> targets_;
  TypedReader* reader_ = nullptr;  // owned by the transport
  std::unique_ptr<Output<msg::ParamChange>> answers_;
  std::atomic<bool> arrived_{false};
  std::atomic<int> queued_{0};
  std::mutex mutex_;  // the reader and the queues
  std::vector<std::vector<msg::ParamChange>> queues_;
  std::mutex publish_mutex_;  // answers_ (its sequence numbers)
};

}  // namespace dyad
