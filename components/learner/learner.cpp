#include "learner.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <future>
#include <thread>

#include <yaml-cpp/yaml.h>

#include <dyad/decode_sample.hpp>

#include "dyad/pvrnn/dataset.hpp"
#include "run_process.hpp"
#include "yaml_file.hpp"

namespace dyad::learner {
namespace {

namespace fs = std::filesystem;

double Seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

// "all" -> {} (every demonstration); "2,0,1" -> {2, 0, 1}.
StatusOr<std::vector<int>> ParseChoice(const std::string& which) {
  if (which == "all") return std::vector<int>{};
  std::vector<int> chosen;
  size_t start = 0;
  while (start <= which.size()) {
    const size_t comma = std::min(which.find(',', start), which.size());
    const std::string item = which.substr(start, comma - start);
    size_t used = 0;
    int k = -1;
    try {
      k = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || k < 0)
      return Status::InvalidArgument("say \"all\" or the demonstrations meant, in order, e.g. \"2,0,1\" (got \"" + which + "\")");
    chosen.push_back(k);
    start = comma + 1;
  }
  return chosen;
}

// OUT/learn-N-YYYYmmdd-HHMMSS (stamped) or OUT/learn-N, made here; never one that exists.
StatusOr<std::string> MakeRunFolder(const std::string& out, uint32_t run, bool stamped) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) return Status::Internal("params.out: cannot create " + out + ": " + ec.message());
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  const std::string base = (fs::path(out) / ("learn-" + std::to_string(run) + (stamped ? std::string("-") + stamp : ""))).string();
  for (int k = 1; k < 100; ++k) {
    const std::string folder = k == 1 ? base : base + "-" + std::to_string(k);
    if (fs::create_directory(folder, ec)) return folder;
    if (ec) return Status::Internal("params.out: cannot create " + folder + ": " + ec.message());
  }
  return Status::Internal("params.out: no free folder name beside " + base);
}

}  // namespace

const char* Learner::Name(Phase phase) {
  switch (phase) {
    case Phase::kIdle: return "idle";
    case Phase::kTraining: return "training";
    case Phase::kTrained: return "trained";
    case Phase::kSwapping: return "swapping";
    case Phase::kDone: return "done";
    case Phase::kFailed: return "failed";
  }
  return "?";
}

void Learner::Enter(Phase phase) {
  phase_ = phase;
  status_msg_.state(Name(phase));
}

void Learner::Describe(ComponentSpec& spec) {
  spec.Summary("Learns from this session: its demonstrations cut into a data set, a model trained on it, swapped into the deliberator.");
  spec.RequiredParam("train", ParamType::kString).Path().Doc("training config (YAML, as for dyad train); dataset and output are the run's");
  spec.RequiredParam("out", ParamType::kString).Path().Doc("folder of the runs (OUT/learn-N-TIME/: dataset/, train.log, model.dpvrnn)");
  spec.Param("learn", "").Live().Doc("set it to start a run: \"all\" or the demonstrations meant, in order, e.g. \"2,0,1\"");
  spec.Param("target", "mind.model").Doc("COMPONENT.PARAM the trained model is given to (the deliberator's live model)");
  spec.Param("swap", "auto").OneOf({"auto", "button"}).Doc("auto: swap as soon as trained; button: when swap_in is set");
  spec.Param("swap_in", "").Live().Doc("set it (any value) to swap in the last trained model");
  spec.Param("epochs", int64_t{0}).Range(0, 100000000).Doc("training epochs (0: the config's)");
  spec.Param("steps", int64_t{72}).Range(2, 100000).Unit("steps").Doc("steps T of every primitive");
  spec.Param("min_samples", int64_t{10}).Range(2, 1000000).Doc("shorter engaged segments are not demonstrations");
  spec.Param("threads", int64_t{1}).Range(0, 256).Doc("the trainer's threads (0: every core; 1 leaves the graph a core; same result)");
  spec.Param("trainer", "").Path().Doc("the dyad executable that trains (empty: the one running this graph)");
  spec.Input<msg::HumanInput>("human").Doc("the person's position and engagement");
  spec.Input<msg::ModelInfo>("model").Optional().Doc("the deliberator's model output: a run is done once the new model steers");
  spec.Output<msg::LearnerStatus>("status").Doc("demonstrations, state, epoch, loss, folder, message: every step");
  spec.Output<msg::ParamChange>("requests").Doc("the swap request: bind to dyad/param_requests");
}

Status Learner::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  train_config_ = p.String("train");
  out_ = p.String("out");
  trainer_ = p.String("trainer").empty() ? tools::ThisExecutable() : p.String("trainer");
  swap_on_button_ = p.String("swap") == "button";
  epochs_ = static_cast<int>(p.Int("epochs"));
  threads_ = static_cast<int>(p.Int("threads"));
  human_ = &ctx.input<msg::HumanInput>("human");
  model_ = &ctx.input<msg::ModelInfo>("model");
  status_ = &ctx.output<msg::LearnerStatus>("status");
  requests_ = &ctx.output<msg::ParamChange>("requests");
  cut_.topic = human_->topic().empty() ? "human" : human_->topic();
  cut_.steps = static_cast<int>(p.Int("steps"));
  cut_.min_samples = static_cast<int>(p.Int("min_samples"));
  cut_.choose_name = "learn";
  cut_.steps_name = "steps";
  cut_.source_name = "the session";
  const std::string target = p.String("target");
  const size_t dot = target.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == target.size())
    return Status::InvalidArgument("params.target: must be COMPONENT.PARAM, got \"" + target + "\"");
  target_component_ = target.substr(0, dot);
  target_param_ = target.substr(dot + 1);
  try {
    const YAML::Node graph = YAML::Load(ctx.graph_yaml());
    if (graph["components"] && graph["components"].IsMap() && !graph["components"][target_component_])
      return Status::InvalidArgument("params.target: no component '" + target_component_ + "' in the graph");
    const YAML::Node config = YAML::LoadFile(train_config_);
    if (epochs_ == 0 && config["epochs"]) epochs_ = config["epochs"].as<int>();
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("params.train: " + train_config_ + ": " + e.what());
  }
  if (epochs_ <= 0) return Status::InvalidArgument("params.epochs: 0 and " + train_config_ + " says no epochs");
  if (trainer_.empty() || !fs::exists(trainer_)) return Status::InvalidArgument("params.trainer: no dyad executable at \"" + trainer_ + "\"");
  if (!requests_->bound()) return Status::InvalidArgument("outputs.requests: not bound (bind it to dyad/param_requests)");
  // The deliberator's answers: a refused swap ends the run (else it would wait for a model that
  // never comes). Without the topic here (a test's context) only the timeout ends it.
  ctx.SubscribeSerialized("dyad/params", [this](const SerializedSample& sample) {
    msg::ParamChange answer;
    if (!DecodeSample(sample.cdr, &answer).ok() || answer.op() != "refused") return;
    MutexLock lock(mutex_);
    if (!swap_request_id_.empty() && answer.request_id() == swap_request_id_) refusal_ = answer.reason();
  }).IgnoreError();
  ctx.PrepareLiveParam(
      "learn", [this](const ParamValue& v) { return PrepareRun(std::get<std::string>(v)); },
      [this](const ParamValue&) { StartTrainer(); });
  ctx.PrepareLiveParam(
      "swap_in",
      [this](const ParamValue&) {
        const Phase phase = phase_;
        return phase == Phase::kTrained
                   ? Status::OK()
                   : Status::FailedPrecondition(std::string("no trained model waits for its swap (the learner is ") + Name(phase) + ")");
      },
      [this](const ParamValue&) {
        if (Status s = AskSwap(ctx_->clock().now_ns()); !s.ok()) Fail("the swap request was not sent: " + s.message());
      });
  status_msg_.component_name(ctx.name());
  status_msg_.loss(NAN);
  status_msg_.elapsed_s(NAN);
  status_msg_.since_demonstration_s(NAN);
  Enter(Phase::kIdle);
  return Status::OK();
}

// Off the step thread (wall clock) or at the step boundary (stepped). It touches only what the
// mutex guards and the atomics; its check of the phase holds because the runtime prepares one
// request of a component at a time, and only the commit (StartTrainer) leaves kIdle for kTraining.
Status Learner::PrepareRun(const std::string& which) {
  const Phase phase = phase_;
  if (phase == Phase::kTraining || phase == Phase::kSwapping)
    return Status::FailedPrecondition("run " + std::to_string(run_) + " is " + Name(phase) + ": one run at a time");
  auto chosen = ParseChoice(which);
  if (!chosen.ok()) return chosen.status();
  analyze::DemonstrationOptions o = cut_;
  o.choose = *chosen;
  PreparedRun run;
  std::vector<analyze::HumanSample> samples;
  {
    MutexLock lock(mutex_);
    samples = samples_;
    run.last_demonstration = last_demonstration_;
  }
  auto demos = analyze::DemonstrationsFromSamples(samples, o);
  if (!demos.ok()) return Status::InvalidArgument(demos.status().message());
  // Under the stepped clock the folder's name is the run's number only: the same run, the same
  // names in the recording.
  auto folder = MakeRunFolder(out_, run_ + 1, !ctx_->stepped());
  if (!folder.ok()) return folder.status();
  run.folder = *folder;
  if (Status s = pvrnn::WriteNrlDataset(demos->dataset, run.folder + "/dataset"); !s.ok()) {
    std::error_code ec;
    fs::remove_all(run.folder, ec);
    return s;
  }
  run.chosen = demos->chosen;
  for (const auto& w : demos->warnings) run.warnings += (run.warnings.empty() ? "" : "; ") + w;
  run.model = run.folder + "/model.dpvrnn";
  run.asked = std::chrono::steady_clock::now();
  MutexLock lock(mutex_);
  prepared_ = std::move(run);
  have_prepared_ = true;
  return Status::OK();
}

void Learner::StartTrainer() {
  PreparedRun run;
  {
    MutexLock lock(mutex_);
    if (!have_prepared_) return;
    run = std::move(prepared_);
    have_prepared_ = false;
  }
  if (trainer_thread_.joinable()) trainer_thread_.join();  // the last run's, ended
  ++run_;
  log_ = TrainingLog();
  log_.epochs = epochs_;
  asked_ = run.asked;
  last_demonstration_of_run_ = run.last_demonstration;
  status_msg_.run(run_);
  status_msg_.chosen(std::vector<int32_t>(run.chosen.begin(), run.chosen.end()));
  status_msg_.folder(run.folder);
  status_msg_.model("");
  status_msg_.message(run.warnings);
  status_msg_.epoch(0);
  status_msg_.epochs(static_cast<uint32_t>(epochs_));
  status_msg_.loss(NAN);
  status_msg_.since_demonstration_s(NAN);
  trained_model_ = run.model;
  log_path_ = run.folder + "/train.log";
  // Everything the trainer writes goes into the run's folder (the config may name a checkpoint
  // or CSV log of its own); paths as YAML strings (--set parses YAML). One thread by default:
  // the graph keeps a core (the result does not depend on the threads, docs/pvrnn.md). A log line
  // every 1% of the epochs, at least every 100 (each costs about one epoch: the prior's
  // reconstruction), so the page's loss curve moves.
  const std::vector<std::string> args = {
      trainer_, "train", train_config_,
      "--set", "dataset=" + tools::YamlQuoted(run.folder + "/dataset"),
      "--set", "output=" + tools::YamlQuoted(run.model),
      "--set", "checkpoint=" + tools::YamlQuoted(run.model + ".ckpt"),
      "--set", "log_csv=" + tools::YamlQuoted(run.model + ".csv"),
      "--set", "epochs=" + std::to_string(epochs_),
      "--set", "threads=" + std::to_string(threads_),
      "--set", "log_every=" + std::to_string(std::clamp(epochs_ / 100, 1, 100))};
  ctx_->log().Info("run " + std::to_string(run_) + ": training on " + std::to_string(run.chosen.size()) + " demonstration(s): " +
                   tools::ShellQuoted(args) + " (log " + log_path_ + ")");
  trainer_ended_ = false;
  trainer_child_.reset();
  Enter(Phase::kTraining);
  // Under the stepped clock the step waits for the trainer (the same run learns at the same step
  // every time); it stays in our process group there, so a Ctrl-C stops it too (it saves its
  // checkpoint and the run fails as interrupted), and the graph with it.
  tools::ChildOptions options;
  options.log = log_path_;
  options.own_group = !ctx_->stepped();
  options.nice = 10;  // the graph's steps come first
  std::promise<void> started;
  std::future<void> running = started.get_future();
  trainer_thread_ = std::thread([this, args, options, started = std::move(started)]() mutable {
    trainer_child_ = std::make_unique<tools::ChildProcess>(args, options);
    started.set_value();
    trainer_status_ = trainer_child_->Wait();
    trainer_ended_ = true;
  });
  running.wait();  // its pid known (or that it never started) before we return
  if (ctx_->stepped()) trainer_thread_.join();
}

void Learner::WatchTrainer() {
  log_.Update(log_path_);
  status_msg_.epoch(static_cast<uint32_t>(std::max<int64_t>(0, log_.epoch)));
  status_msg_.loss(log_.loss);
  if (!trainer_ended_) return;
  if (trainer_thread_.joinable()) trainer_thread_.join();
  const tools::ExitStatus status = trainer_status_;
  if (status.never_started()) return Fail("could not run the trainer " + trainer_ + ": " + status.ToString());
  if (!status.ok() || !fs::exists(trained_model_))
    return Fail("the trainer " + std::string(status.signaled() ? "was " : "") + status.ToString() + ": " +
                (log_.last_error.empty() ? log_.last_line : log_.last_error) + " (log " + log_path_ + ")");
  status_msg_.model(trained_model_);
  Enter(Phase::kTrained);
  ctx_->log().Info("run " + std::to_string(run_) + ": trained in " + std::to_string(Seconds(std::chrono::steady_clock::now() - asked_)) +
                   " s, loss " + std::to_string(log_.loss) + ": " + trained_model_);
  if (!swap_on_button_)
    if (Status s = AskSwap(ctx_->clock().now_ns()); !s.ok()) Fail("the swap request was not sent: " + s.message());
}

void Learner::Fail(const std::string& why) {
  Enter(Phase::kFailed);
  status_msg_.message(why);
  ctx_->log().Error("run " + std::to_string(run_) + ": " + why);
}

Status Learner::AskSwap(int64_t now_ns) {
  msg::ParamChange request;
  request.graph_name(ctx_->graph_name());
  request.component_name(target_component_);
  request.param_name(target_param_);
  request.op("set");
  request.value(tools::YamlQuoted(trained_model_));
  request.who("learner " + ctx_->name());
  // Unique per request (as dyad/param_requests wants): the run, this process and its clock.
  request.request_id(ctx_->name() + "/run" + std::to_string(run_) + "/" + std::to_string(::getpid()) + "/" +
                     std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  {
    MutexLock lock(mutex_);
    swap_request_id_ = request.request_id();
    refusal_.clear();
  }
  if (Status s = requests_->Publish(request); !s.ok()) return s;
  swap_asked_ns_ = now_ns;
  Enter(model_->bound() ? Phase::kSwapping : Phase::kDone);
  status_msg_.message("asked " + target_component_ + "." + target_param_ + " = " + trained_model_ +
                      (model_->bound() ? "" : " (its answer is on dyad/params)"));
  return Status::OK();
}

// Swapping ends with the deliberator's model output naming the new model (done), its refusal
// on dyad/params, or a minute of neither (failed: the model in force stays).
void Learner::WatchSwap(int64_t now_ns) {
  for (const msg::ModelInfo& m : model_->received()) {
    if (m.path() != trained_model_) continue;
    Enter(Phase::kDone);
    if (!ctx_->stepped())
      status_msg_.since_demonstration_s(Seconds(std::chrono::steady_clock::now() - last_demonstration_of_run_));
    status_msg_.message("the new model steers from step " + std::to_string(m.step()) + " (sha256 " + m.sha256().substr(0, 12) + ")");
    ctx_->log().Info("run " + std::to_string(run_) + ": " + status_msg_.message() +
                     (ctx_->stepped() ? "" : ", " + std::to_string(status_msg_.since_demonstration_s()) + " s after the last demonstration"));
    return;
  }
  std::string refusal;
  {
    MutexLock lock(mutex_);
    refusal = refusal_;
  }
  if (!refusal.empty()) return Fail(target_component_ + "." + target_param_ + " refused the model: " + refusal);
  if (now_ns - swap_asked_ns_ > 60'000'000'000)
    Fail("no word in 60 s from " + target_component_ + " that the model steers (is requests bound to dyad/param_requests?)");
}

// The human's samples: a demonstration is complete at the first sample after it (its release).
void Learner::TakeSamples() {
  bool released = false;
  MutexLock lock(mutex_);
  for (const msg::HumanInput& h : human_->received()) {
    const analyze::HumanSample s{static_cast<double>(h.header().stamp_ns()), h.x(), h.y(), h.engaged()};
    if (s.engaged) {
      holding_.push_back(s);
      continue;
    }
    released = released || !holding_.empty();
    samples_.insert(samples_.end(), holding_.begin(), holding_.end());
    samples_.push_back(s);
    holding_.clear();
  }
  if (!released) return;
  auto demos = analyze::DemonstrationsFromSamples(samples_, cut_);  // numeric: well under a millisecond
  if (!demos.ok() || demos->segments.size() == demonstrations_) return;  // too short to be one
  demonstrations_ = demos->segments.size();
  last_demonstration_ = std::chrono::steady_clock::now();
  std::vector<double> start, duration;
  std::vector<int32_t> laps;
  for (const auto& seg : demos->segments) start.push_back(seg.start_s), duration.push_back(seg.duration_s), laps.push_back(seg.laps);
  status_msg_.segment_start_s(std::move(start));
  status_msg_.segment_duration_s(std::move(duration));
  status_msg_.segment_laps(std::move(laps));
}

Status Learner::Step(const StepInfo& info) {
  TakeSamples();
  if (phase_ == Phase::kTraining) WatchTrainer();
  if (phase_ == Phase::kSwapping) WatchSwap(info.now_ns);
  if ((phase_ == Phase::kTraining || phase_ == Phase::kSwapping) && !ctx_->stepped())
    status_msg_.elapsed_s(Seconds(std::chrono::steady_clock::now() - asked_));
  return status_->Publish(status_msg_);
}

Status Learner::Deactivate() {
  if (!trainer_thread_.joinable()) return Status::OK();
  if (!trainer_ended_) {
    // Stopped as by Ctrl-C (the trainer saves its checkpoint), killed if it does not end in 5 s.
    trainer_child_->Stop(std::chrono::seconds(5), SIGINT);
    ctx_->log().Info("run " + std::to_string(run_) + ": training stopped with the graph at epoch " + std::to_string(log_.epoch));
  }
  trainer_thread_.join();
  return Status::OK();
}

Learner::~Learner() {
  // A graph that never activated, or a test: the trainer is not left behind.
  if (!trainer_thread_.joinable()) return;
  if (!trainer_ended_) trainer_child_->Stop(std::chrono::milliseconds(0), SIGKILL);
  trainer_thread_.join();
}

}  // namespace dyad::learner

DYAD_PLUGIN(registry) { registry.Add<dyad::learner::Learner>("learner"); }
