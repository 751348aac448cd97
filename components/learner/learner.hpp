/// The `learner` component: "learn from this session". It keeps the session's demonstrations (the
/// human's engaged segments), and when asked (`learn`, a live parameter: the experimenter's page,
/// `dyad param set`) cuts them into a data set as `dyad dataset from-recording` does, trains a
/// model on it in a background process (`dyad train` with the `train` config) and asks the
/// deliberator to swap it in (`target`, its live `model` parameter), which it does without
/// stopping. Its status (segments, epoch, loss, the swap) is what the experimenter's page shows.
///
/// @component learner
/// rate_hz: periodic, or `trigger: human` (every sample must be seen: a periodic learner slower
///   than the human needs the human topic's depth to hold the samples of one of its periods)
/// inputs:
///   human (HumanInput): the person's position and whether they hold the robot; each completed
///     engaged segment of at least `min_samples` samples is a demonstration (numbered 0, 1, ...)
///   model (ModelInfo, optional): the deliberator's `model` output; when bound, a run is "done"
///     once the deliberator steers with the new model (and says how long that took), not when asked
/// outputs:
///   status (LearnerStatus): every step: the demonstrations so far and the run's state, epoch,
///     loss, folder and message
///   requests (ParamChange): the swap request; bind it to dyad/param_requests
/// params:
///   train (string, required): training config (YAML, as for `dyad train`): the model's layers,
///     encoding, Adam, epochs; its `dataset` and `output` are replaced by the run's own
///   out (string, required): folder of the runs: OUT/learn-N-TIME/ holds dataset/, train.log and
///     model.dpvrnn (nothing is ever overwritten)
///   learn (string, live, ""): set it to start a run: "all" (every demonstration, in order) or the
///     demonstrations meant, in order, e.g. "2,0,1" (primitive k <- demonstration k-th in the list).
///     Refused while a run trains, when a demonstration does not exist, or with none
///   target (string, mind.model): COMPONENT.PARAM the trained model is given to
///   swap (string, auto): auto (as soon as it is trained) | button (when `swap_in` is set)
///   swap_in (string, live, ""): set it (any value) to swap in the last trained model
///   epochs (int, 0): training epochs (0: the config's)
///   steps (int, 72), min_samples (int, 10): as `dyad dataset from-recording`'s --steps and
///     --min-samples
///   trainer (string, ""): the dyad executable that trains (default: the one running this graph)
/// @endcomponent
///
/// On the wall clock the training runs beside the graph (the learner only watches its log); on
/// the stepped clock the learner's step waits for it, so a stepped run learns, and swaps, at the
/// same step every time. A run that fails (the trainer's exit status and its last line) leaves the
/// model in force; stopping the graph stops a training (SIGINT, then SIGKILL after 5 s).
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/thread_annotations.hpp>

#include "child_process.hpp"
#include "demonstrations.hpp"
#include "training_log.hpp"

namespace dyad::learner {

class Learner final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;
  Status Deactivate() override;
  ~Learner() override;

 private:
  using WallTime = std::chrono::steady_clock::time_point;
  // The `learn` value prepared off the step thread: the data set written, the trainer not started.
  struct PreparedRun {
    std::string folder, model;
    std::vector<int> chosen;
    std::string warnings;
    WallTime asked, last_demonstration;
  };
  // Written on the step thread, read by the live params' preparations too.
  enum class Phase { kIdle, kTraining, kTrained, kSwapping, kDone, kFailed };
  static const char* Name(Phase phase);
  void Enter(Phase phase);
  Status PrepareRun(const std::string& which);  // cuts and writes the data set (PrepareLiveParam)
  void StartTrainer();                          // the commit of `learn`, on the step thread
  void WatchTrainer();
  Status AskSwap(int64_t now_ns);
  void WatchSwap(int64_t now_ns);
  void TakeSamples();
  void Fail(const std::string& why);

  Context* ctx_ = nullptr;
  Input<msg::HumanInput>* human_ = nullptr;  // owned by the runtime
  Input<msg::ModelInfo>* model_ = nullptr;   // owned by the runtime
  Output<msg::LearnerStatus>* status_ = nullptr;
  Output<msg::ParamChange>* requests_ = nullptr;
  std::string train_config_, out_, trainer_, target_component_, target_param_;
  bool swap_on_button_ = false;
  int epochs_ = 0, threads_ = 1;
  analyze::DemonstrationOptions cut_;

  // Guards the members marked GUARDED_BY below (PrepareRun runs off the step
  // thread, dyad/params answers arrive on a delivering thread).
  Mutex mutex_;
  // the session up to the end of its last demonstration
  std::vector<analyze::HumanSample> samples_ GUARDED_BY(mutex_);
  WallTime last_demonstration_ GUARDED_BY(mutex_){};  // when the newest demonstration was completed
  PreparedRun prepared_ GUARDED_BY(mutex_);
  bool have_prepared_ GUARDED_BY(mutex_) = false;
  std::string swap_request_id_ GUARDED_BY(mutex_);  // of the swap asked; its refusal on dyad/params ends it
  std::string refusal_ GUARDED_BY(mutex_);

  std::atomic<Phase> phase_{Phase::kIdle};
  std::atomic<uint32_t> run_{0};  // runs started

  // The trainer: started and waited for by a thread of its own, which lives exactly as long as the
  // trainer (a child's PR_SET_PDEATHSIG follows the thread that forked it, not the process).
  // trainer_child_ is set before StartTrainer returns (so a Deactivate right after stops it) and
  // stays until the next run starts; trainer_status_ is written by trainer_thread_ before
  // trainer_ended_ is set, and read after.
  std::thread trainer_thread_;
  std::unique_ptr<tools::ChildProcess> trainer_child_;
  std::atomic<bool> trainer_ended_{false};
  tools::ExitStatus trainer_status_;

  // The step thread's own.
  std::vector<analyze::HumanSample> holding_;  // the segment being drawn (not a demonstration yet)
  size_t demonstrations_ = 0;
  msg::LearnerStatus status_msg_;
  WallTime asked_{}, last_demonstration_of_run_{};
  int64_t swap_asked_ns_ = 0;  // runtime clock
  TrainingLog log_;
  std::string trained_model_, log_path_;  // of the current run
};

}  // namespace dyad::learner
