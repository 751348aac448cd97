#include "sweep_runner.hpp"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <system_error>
#include <thread>

#include <nlohmann/json.hpp>

#include "build_report.hpp"
#include "job_end.hpp"
#include "run_process.hpp"
#include "run_status.hpp"
#include "text_output.hpp"

namespace dyad::sweep {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string Tail(const std::string& path, size_t lines) {
  std::ifstream in(path);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (last.size() > lines) last.pop_front();
  }
  std::string out;
  for (const auto& l : last) out += l + "\n";
  return out;
}

std::atomic<int> g_stop_signal{0};  // lock-free: set in a handler, read by the workers
static_assert(std::atomic<int>::is_always_lock_free);
extern "C" void OnSweepStopSignal(int signal) { g_stop_signal.store(signal); }

// `args` with its output in `log`, in a process group of its own (SIGINT when we die); a stop
// signal stops it (ChildProcess::Stop: SIGINT to its group, SIGKILL after kStopGraceS).
// *stopped: a stop came before it ended (how it ended is then for nobody).
tools::ExitStatus RunChild(const std::vector<std::string>& args, const std::string& log, bool* stopped) {
  *stopped = g_stop_signal.load() != 0;
  if (*stopped) return {};
  tools::ChildOptions options;
  options.log = log;
  options.own_group = true;
  tools::ChildProcess child(args, options);
  for (;;) {
    if (std::optional<tools::ExitStatus> end = child.Poll()) return *end;
    if (g_stop_signal.load() != 0) {
      *stopped = true;
      return child.Stop(std::chrono::milliseconds(static_cast<int64_t>(kStopGraceS * 1000)), SIGINT);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// `dyad analyze --no-plots --duration planned_s`, in this process (a second process per run cost
// a fifth of a short run); its warnings go to analyze.log beside the report. A recording cut
// short or shorter than planned gets report/incomplete.txt (analyze::IncompleteReason), which
// marks the run `incomplete` in sweep.csv.
Status Analyze(const std::string& recording, const std::string& report_dir, double planned_s) {
  std::ostringstream warnings;
  auto report = analyze::BuildReport(recording, warnings);
  std::ofstream(fs::path(report_dir).parent_path() / "analyze.log") << warnings.str();
  if (!report.ok()) return report.status();
  report->planned_s = planned_s;
  return analyze::WriteReport(*report, report_dir);
}

// A failure: `text` into `file`; when that cannot be written, its first line is the reason.
JobEnd Failed(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  out.close();
  if (out) return {JobOutcome::kFailed, ""};
  return {JobOutcome::kFailed, text.substr(0, text.find('\n')) + " (and " + file.string() + " cannot be written)"};
}

// `dir` made (or there) and `stale` gone; else why not.
std::string PrepareFolder(const fs::path& dir, const fs::path& stale) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!ec && !fs::is_directory(dir, ec)) ec = std::make_error_code(std::errc::not_a_directory);
  if (ec) return "cannot make its folder " + dir.string() + ": " + ec.message();
  if (fs::remove(stale, ec); ec) return "cannot remove " + stale.string() + ": " + ec.message();
  return "";
}

// One run, start to end (see the header).
JobEnd DoRun(const SweepPlan& plan, const SweepRun& run, const RunnerOptions& o) {
  const fs::path dir = fs::path(o.out) / "runs" / run.id;
  std::error_code ec;
  if (fs::exists(dir / "metrics.json", ec)) return {JobOutcome::kSkipped, ""};
  if (std::string why = PrepareFolder(dir, dir / "failed.txt"); !why.empty()) return {JobOutcome::kFailed, why};
  std::vector<std::string> run_args = {o.dyad, "run", plan.graph, "--quiet", "--duration", std::to_string(plan.duration_s)};
  for (const auto& s : run.sets) run_args.insert(run_args.end(), {"--set", s});
  run_args.insert(run_args.end(), {"--set", plan.recorder + ".file=" + (dir / "rec.mcap").string()});
  if (run.training >= 0) {
    const SweepTraining& training = plan.trainings[static_cast<size_t>(run.training)];
    const std::string model = ModelPath(o.out, training);
    run_args.insert(run_args.end(), {"--set", plan.model_key + "=" + model});
    if (!fs::exists(model, ec))
      return Failed(dir / "failed.txt", "its model " + model + " was not trained (see " +
                                            (fs::path(o.out) / "models" / (training.id + ".log")).string() + ")\n");
  }
  bool stopped = false;
  const tools::ExitStatus exit = RunChild(run_args, (dir / "run.log").string(), &stopped);
  const JobEnd end = ClassifyRunChild(stopped, exit);
  if (end.outcome == JobOutcome::kStopped) return end;
  if (end.outcome == JobOutcome::kFailed)
    return Failed(dir / "failed.txt", tools::ShellQuoted(run_args) + "\n" + end.why + "; the end of run.log:\n" +
                                          Tail((dir / "run.log").string(), 20));
  if (Status s = Analyze((dir / "rec.mcap").string(), (dir / "report").string(), plan.duration_s); !s.ok())
    return Failed(dir / "failed.txt", "dyad analyze " + (dir / "rec.mcap").string() + ": " + s.message() + "\n");
  fs::copy_file(dir / "report" / "metrics.json", dir / "metrics.json.new", fs::copy_options::overwrite_existing, ec);
  if (!ec) fs::rename(dir / "metrics.json.new", dir / "metrics.json", ec);
  if (ec) return Failed(dir / "failed.txt", "cannot keep the metrics: " + ec.message() + "\n");
  return {JobOutcome::kOk, ""};
}

std::string Duration(double s) {
  char buf[32];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(s / 60) % 60);
  else std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  return buf;
}

// What Pool runs: job i, what it is (for the log), and the file that says why it failed.
struct PoolJobs {
  std::function<JobEnd(size_t)> run;
  std::function<std::string(size_t)> what, why_file;
};

// The log line of a job that ended, under Pool's lock.
struct PoolProgress {
  size_t count = 0, finished = 0, executed = 0;
  Clock::time_point t0 = Clock::now();

  void Line(std::ostream& log, const std::string& what, const JobEnd& end, const std::string& why_file, double secs) {
    const JobOutcome outcome = end.outcome;
    ++finished;
    if (outcome != JobOutcome::kSkipped) ++executed;
    std::string how = OutcomeName(outcome);
    if (outcome == JobOutcome::kFailed) how += " (" + (end.why.empty() ? why_file : end.why) + ")";
    const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    const size_t left = count - finished;
    log << "[" << finished << "/" << count << "] " << what << ": " << how;
    if (outcome != JobOutcome::kSkipped) {
      char s[32];
      std::snprintf(s, sizeof s, " in %.1f s", secs);
      log << s;
    }
    if (left > 0 && executed > 0 && outcome != JobOutcome::kStopped)
      log << ", about " << Duration(elapsed / static_cast<double>(executed) * static_cast<double>(left)) << " left";
    log << "\n" << std::flush;
  }
};

// Runs jobs 0..count-1, `workers` at once; after each, a line to `log`: its count, what it was,
// how it ended, and the estimated time left. A stop signal ends the loop: the jobs not done are
// listed in the result.
RunnerResult Pool(size_t count, int workers, std::ostream& log, const PoolJobs& jobs) {
  RunnerResult result;
  std::atomic<size_t> next{0};
  std::mutex mutex;  // guards result, log, progress, done
  PoolProgress progress;
  progress.count = count;
  std::vector<bool> done(count, false);
  auto worker = [&] {
    for (size_t i; g_stop_signal.load() == 0 && (i = next.fetch_add(1)) < count;) {
      const auto start = Clock::now();
      const JobEnd end = jobs.run(i);
      const double secs = std::chrono::duration<double>(Clock::now() - start).count();
      std::lock_guard<std::mutex> lock(mutex);
      if (end.outcome == JobOutcome::kSkipped) ++result.skipped;
      else if (end.outcome == JobOutcome::kOk) ++result.ran;
      else if (end.outcome == JobOutcome::kFailed) ++result.failed;
      done[i] = end.outcome != JobOutcome::kStopped;
      progress.Line(log, jobs.what(i), end, jobs.why_file(i), secs);
    }
  };
  std::vector<std::thread> threads;
  for (int w = 0; w < std::max(1, workers); ++w) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  result.signal = g_stop_signal.load();
  if (result.signal != 0)
    for (size_t i = 0; i < count; ++i)
      if (!done[i]) result.not_done.push_back(i);
  return result;
}

JobEnd Train(const SweepPlan& plan, const SweepTraining& training, const RunnerOptions& o) {
  const std::string model = ModelPath(o.out, training);
  const fs::path dir = fs::path(model).parent_path();
  std::error_code ec;
  if (fs::exists(model, ec)) return {JobOutcome::kSkipped, ""};
  if (std::string why = PrepareFolder(dir, dir / (training.id + ".failed.txt")); !why.empty()) return {JobOutcome::kFailed, why};
  std::vector<std::string> args = {o.dyad, "train", plan.train_config};
  for (const auto& s : training.sets) args.insert(args.end(), {"--set", s});
  args.insert(args.end(), {"--set", "output=" + model});
  // Workers already fill the cores: one thread per training (same bits whatever the count).
  if (o.workers > 1) args.insert(args.end(), {"--set", "threads=1"});
  const std::string log = (dir / (training.id + ".log")).string();
  bool stopped = false;
  const tools::ExitStatus exit = RunChild(args, log, &stopped);
  const JobEnd end = ClassifyTraining(stopped, exit, fs::exists(model, ec));
  if (end.outcome != JobOutcome::kFailed) return end;
  return Failed(dir / (training.id + ".failed.txt"),
                tools::ShellQuoted(args) + "\n" + end.why + "; the end of its log:\n" + Tail(log, 20));
}

std::string Params(const std::vector<std::pair<std::string, std::string>>& params) {
  std::string s;
  for (const auto& [k, v] : params) s += " " + k + "=" + v;
  return s;
}

}  // namespace

StopOnSignals::StopOnSignals() {
  g_stop_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = OnSweepStopSignal;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int_);  // over SIG_IGN too: a script's background sweep stops on Ctrl-C's SIGINT
  sigaction(SIGTERM, &sa, &old_term_);
}

StopOnSignals::~StopOnSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int StopOnSignals::Received() { return g_stop_signal.load(); }

RunnerResult RunSweep(const SweepPlan& plan, const RunnerOptions& options, std::ostream& log) {
  PoolJobs jobs;
  jobs.run = [&](size_t i) { return DoRun(plan, plan.runs[i], options); };
  jobs.what = [&](size_t i) { return plan.runs[i].id + Params(plan.runs[i].params) + " seed=" + std::to_string(plan.runs[i].seed); };
  jobs.why_file = [&](size_t i) { return "runs/" + plan.runs[i].id + "/failed.txt"; };
  return Pool(plan.runs.size(), options.workers, log, jobs);
}

RunnerResult TrainModels(const SweepPlan& plan, const std::vector<SweepTraining>& trainings, const RunnerOptions& options,
                         std::ostream& log) {
  PoolJobs jobs;
  jobs.run = [&](size_t i) { return Train(plan, trainings[i], options); };
  jobs.what = [&](size_t i) { return "model " + trainings[i].id + Params(trainings[i].params); };
  jobs.why_file = [&](size_t i) { return "models/" + trainings[i].id + ".failed.txt"; };
  return Pool(trainings.size(), options.workers, log, jobs);
}

Status WriteSweepCsv(const SweepPlan& plan, const std::string& out) {
  std::vector<std::string> metric_names;
  std::vector<nlohmann::ordered_json> metrics(plan.runs.size());
  std::vector<RunStatus> status(plan.runs.size(), RunStatus::kMissing);
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const fs::path dir = fs::path(out) / "runs" / plan.runs[i].id;
    std::ifstream in(dir / "metrics.json");
    if (in) {
      metrics[i] = nlohmann::ordered_json::parse(in, nullptr, false);
      if (!metrics[i].is_object()) return Status::DataLoss((dir / "metrics.json").string(), "not a JSON object");
      // A recording cut short or shorter than planned: its numbers are in the table, marked, and
      // out of the plots (which take the `ok` rows).
      std::error_code ec;
      status[i] = fs::exists(dir / "report" / "incomplete.txt", ec) ? RunStatus::kIncomplete : RunStatus::kOk;
      if (metric_names.empty())
        for (const auto& [name, value] : metrics[i].items()) metric_names.push_back(name);
    } else if (std::error_code ec; fs::exists(dir / "failed.txt", ec)) {
      status[i] = RunStatus::kFailed;
    }
  }
  std::ostringstream csv;
  csv << "run,status";
  for (const auto& p : plan.parameters) csv << ',' << tools::CsvCell(p);
  csv << ",seed";
  for (const auto& m : metric_names) csv << ',' << tools::CsvCell(m);
  csv << '\n';
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const SweepRun& run = plan.runs[i];
    csv << run.id << ',' << ToString(status[i]);
    for (const auto& p : plan.parameters) {
      std::string v;
      for (const auto& [k, value] : run.params)
        if (k == p) v = value;
      csv << ',' << tools::CsvCell(v);
    }
    csv << ',' << run.seed;
    for (const auto& m : metric_names) {
      csv << ',';
      // Exact, as metrics.json has it: the plots' means are of the runs' doubles.
      if (metrics[i].is_object() && metrics[i].contains(m) && metrics[i][m].is_number())
        csv << tools::CsvNumber(metrics[i][m].get<double>());
    }
    csv << '\n';
  }
  const fs::path path = fs::path(out) / "sweep.csv";
  std::ofstream f(path.string() + ".new", std::ios::binary | std::ios::trunc);
  f << csv.str();
  f.close();
  std::error_code ec;
  if (f) fs::rename(path.string() + ".new", path, ec);
  if (!f || ec) return Status::IOError(path.string(), "cannot write");
  return Status::OK();
}

}  // namespace dyad::sweep
