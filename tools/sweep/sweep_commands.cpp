#include "sweep_commands.hpp"

#include <CLI/CLI.hpp>

#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include "exit_code.hpp"
#include "run_process.hpp"
#include "sweep_plan.hpp"
#include "sweep_runner.hpp"
#include "sweep_slurm.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;
using tools::ExitCode;
using enum tools::ExitCode;

struct Options {
  std::string file, out;
  int workers = 0;
  std::vector<std::string> plugins;
  bool plots = true, dry_run = false;
  bool slurm = false, collect = false, train_only = false;
  std::string task;  // "i/N": this array task's chunk only
  sweep::SlurmOptions slurm_options;
};

tools::ExitStatus Plot(const std::string& csv, const std::string& dir) {
  return tools::RunDyadScript("plot_sweep.py", {csv, dir});
}

// Back to the folder it started in, whatever happens (the command may run inside a test binary).
struct RestoreCwd {
  std::filesystem::path cwd;
  ~RestoreCwd() {
    std::error_code ec;
    fs::current_path(cwd, ec);
  }
};

void Plots(const Options& o, const fs::path& out) {
  if (!o.plots) return;
  if (tools::ExitStatus rc = Plot((out / "sweep.csv").string(), (out / "plots").string()); !rc.ok())
    std::cerr << "dyad sweep: warning: the plots were not drawn (python3 with matplotlib; " << rc.ToString() << ")\n";
  else
    std::cout << "plots: " << (out / "plots").string() << "/\n";
}

// A stop signal ended the jobs: what is missing, and how to finish them. `what(i)` names job i.
template <typename What>
ExitCode Stopped(const std::string& name, const sweep::RunnerResult& r, const std::string& jobs, What what) {
  std::cout << "sweep " << name << ": stopped by " << (r.signal == SIGINT ? "SIGINT" : "SIGTERM") << ": " << r.ran << " ran, "
            << r.skipped << " done before, " << r.failed << " failed, " << r.not_done.size() << " " << jobs << " missing:\n";
  for (size_t i : r.not_done) std::cout << "  " << what(i) << "\n";
  std::cout << "the finished ones are kept: the same command again runs the missing ones\n" << std::flush;
  return kInterrupted;  // for SIGTERM too: its runs were stopped as by Ctrl-C
}

// The runs of `plan` here, `workers` at once; with `table`, then sweep.csv and the plots.
ExitCode RunHere(const Options& o, const sweep::SweepPlan& plan, const fs::path& out, int workers, bool table) {
  sweep::StopOnSignals stop_on_signals;
  std::error_code ec;
  if (fs::create_directories(out / "runs", ec); ec) {
    std::cerr << "dyad sweep: " << out.string() << ": " << ec.message() << "\n";
    return kFailure;
  }
  const sweep::RunnerOptions runner{out.string(), workers, tools::ThisExecutable()};
  // A Slurm task of runs does not train: the training job before it did (or failed, said per run).
  if (o.task.empty() && !plan.trainings.empty()) {
    std::cout << "training " << plan.trainings.size() << " model" << (plan.trainings.size() == 1 ? "" : "s") << " into "
              << (out / "models").string() << "\n";
    const sweep::RunnerResult t = sweep::TrainModels(plan, plan.trainings, runner, std::cout);
    if (t.signal != 0) return Stopped(plan.name, t, "models (and every run)", [&](size_t i) { return "model " + plan.trainings[i].id; });
  }
  const sweep::RunnerResult r = sweep::RunSweep(plan, runner, std::cout);
  if (r.signal != 0) {
    if (Status s = table ? sweep::WriteSweepCsv(plan, out.string()) : Status::OK(); !s.ok())  // the others: missing
      std::cerr << "dyad sweep: " << s.message() << "\n";
    return Stopped(plan.name, r, "runs", [&](size_t i) {
      std::string what = plan.runs[i].id;
      for (const auto& [key, value] : plan.runs[i].params) what += " " + key + "=" + value;
      return what + " seed=" + std::to_string(plan.runs[i].seed);
    });
  }
  std::cout << "sweep " << plan.name << (o.task.empty() ? "" : " task " + o.task) << ": " << r.ran << " ran, " << r.skipped
            << " done before, " << r.failed << " failed";
  if (!table) {
    std::cout << "\n";
    return r.failed > 0 ? kFailure : kOk;
  }
  if (Status s = sweep::WriteSweepCsv(plan, out.string()); !s.ok()) {
    std::cerr << "\ndyad sweep: " << s.message() << "\n";
    return kFailure;
  }
  std::cout << "; table: " << (out / "sweep.csv").string() << "\n" << std::flush;
  if (r.ran + r.skipped > 0) Plots(o, out);
  return r.failed > 0 ? kFailure : kOk;
}

// --collect: the table of what the runs left in OUT (the Slurm array's last job, or by hand).
ExitCode Collect(const Options& o, const sweep::SweepPlan& plan, const fs::path& out) {
  if (!fs::is_directory(out / "runs")) {
    std::cerr << "dyad sweep --collect: " << out.string() << ": no runs in this folder (none has started yet, or -o names another)\n";
    return kFailure;
  }
  if (Status s = sweep::WriteSweepCsv(plan, out.string()); !s.ok()) {
    std::cerr << "dyad sweep: " << s.message() << "\n";
    return kFailure;
  }
  size_t ok = 0, failed = 0;
  for (const auto& run : plan.runs) {
    ok += fs::exists(out / "runs" / run.id / "metrics.json");
    failed += !fs::exists(out / "runs" / run.id / "metrics.json") && fs::exists(out / "runs" / run.id / "failed.txt");
  }
  const size_t missing = plan.runs.size() - ok - failed;
  std::cout << "sweep " << plan.name << " collected: " << ok << " ok, " << failed << " failed, " << missing
            << " missing; table: " << (out / "sweep.csv").string() << "\n" << std::flush;
  if (ok > 0) Plots(o, out);
  if (missing > 0)
    std::cerr << "dyad sweep: " << missing << " runs have not run (tasks still queued, or lost): `squeue`, then submit again (finished runs are skipped)\n";
  return failed + missing > 0 ? kFailure : kOk;
}

// --train-only: the models (this task's chunk of them), no runs: a Slurm training task.
ExitCode TrainOnly(const Options& o, const sweep::SweepPlan& plan, const fs::path& out, int workers, sweep::TaskSlice task) {
  sweep::StopOnSignals stop_on_signals;
  const auto trainings = o.task.empty() ? plan.trainings : sweep::TaskChunk(plan.trainings, task);
  std::cout << "sweep " << plan.name << ": " << trainings.size() << " of " << plan.trainings.size() << " models into "
            << (out / "models").string() << "\n";
  const sweep::RunnerResult r = sweep::TrainModels(plan, trainings, sweep::RunnerOptions{out.string(), workers, tools::ThisExecutable()}, std::cout);
  if (r.signal != 0) return Stopped(plan.name, r, "models", [&](size_t i) { return "model " + trainings[i].id; });
  std::cout << "sweep " << plan.name << ": " << r.ran << " trained, " << r.skipped << " there before, " << r.failed << " failed\n";
  return r.failed > 0 ? kFailure : kOk;
}

ExitCode Submit(const Options& o, const sweep::SweepPlan& plan, const fs::path& file, const fs::path& out) {
  auto job = sweep::SubmitToSlurm(plan, file.string(), out.string(), tools::ThisExecutable(), o.plugins, o.plots, o.slurm_options);
  if (!job.ok()) {
    std::cerr << "dyad sweep --slurm: " << job.status().message() << "\n";
    return kFailure;
  }
  if (!job->train_id.empty())
    std::cout << "submitted: job " << job->train_id << " trains " << plan.trainings.size() << " models ("
              << job->train_tasks << " array tasks; logs " << (out / "slurm" / "train-N.log").string() << "); the runs wait for it\n";
  std::cout << "submitted: job " << job->array_id << " (" << job->tasks << " array tasks; logs "
            << (out / "slurm" / "task-N.log").string() << "), then job " << job->collect_id << " writes "
            << (out / "sweep.csv").string() << "\nwatch: squeue -j " << (job->train_id.empty() ? "" : job->train_id + ",")
            << job->array_id << "," << job->collect_id << "\n";
  return kOk;
}

ExitCode RunSweepCommand(Options o) {
  std::error_code ec;
  const fs::path file = fs::absolute(o.file, ec);
  // Paths in the sweep file (its graph, its set: values) are relative to it, as a graph's are.
  const fs::path cwd = fs::current_path(ec);
  RestoreCwd restore{cwd};
  sweep::TaskSlice task;
  if (!o.task.empty())
    if (Status s = sweep::ParseTask(o.task, &task); !s.ok()) {
      std::cerr << "dyad sweep: " << s.message() << "\n";
      return kBadInput;
    }
  if (fs::current_path(file.parent_path(), ec); ec) {
    std::cerr << "dyad sweep: " << o.file << ": cannot enter its folder: " << ec.message() << "\n";
    return kBadInput;
  }
  std::vector<Diagnostic> problems;
  sweep::SweepPlan plan = sweep::LoadSweep(file.string(), o.plugins, &problems);
  if (!problems.empty()) {
    for (const auto& p : problems) std::cerr << p.ToString() << "\n";
    std::cerr << o.file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << ", nothing was run\n";
    return kBadInput;
  }
  const fs::path out = o.out.empty() ? cwd / ("sweep-" + plan.name) : fs::absolute(cwd / o.out);
  if (o.collect) return Collect(o, plan, out);
  if (o.slurm) return Submit(o, plan, file, out);
  const int workers = o.workers > 0 ? o.workers : std::max(1u, std::thread::hardware_concurrency());
  if (o.train_only) return TrainOnly(o, plan, out, workers, task);
  const size_t all = plan.runs.size();
  if (!o.task.empty()) plan.runs = sweep::TaskChunk(plan.runs, task);
  std::cout << "sweep " << plan.name << ": " << plan.runs.size() << " runs";
  if (!o.task.empty()) std::cout << " (task " << o.task << " of " << all << " runs)";
  std::cout << " of " << plan.graph;
  if (!plan.trainings.empty()) std::cout << " with " << plan.trainings.size() << " trained model" << (plan.trainings.size() == 1 ? "" : "s");
  std::cout << " (" << plan.duration_s << " s each, stepped), " << workers << " at once, into "
            << out.string() << "\n";
  if (o.dry_run) {
    for (const auto& t : plan.trainings) {
      std::cout << "model " << t.id << ": dyad train " << plan.train_config;
      for (const auto& s : t.sets) std::cout << " --set " << s;
      std::cout << "\n";
    }
    for (const auto& r : plan.runs) {
      std::cout << r.id;
      for (const auto& s : r.sets) std::cout << " --set " << s;
      std::cout << "\n";
    }
    return kOk;
  }
  return RunHere(o, plan, out, workers, o.task.empty());
}

}  // namespace

void AddSweepCommands(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("sweep", "Run a grid of stepped experiments on every core; one table of their metrics (docs/sweep.md)");
  cmd->add_option("sweep", o->file, "Sweep file (YAML)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", o->out, "Sweep folder (default ./sweep-NAME); a rerun resumes it");
  cmd->add_option("-j,--workers", o->workers, "Runs at once (default: the cores)")->check(CLI::Range(1, 1024));
  cmd->add_option("--plugins", o->plugins, "Extra plugin file or folder (repeatable)");
  cmd->add_flag("!--no-plots", o->plots, "sweep.csv only");
  auto* dry = cmd->add_flag("--dry-run", o->dry_run, "check the sweep file and list its runs; run nothing");
  auto* task = cmd->add_option("--task", o->task, "Run only chunk I of N (I counted from 0): what a Slurm array task runs");
  auto* collect = cmd->add_flag("--collect", o->collect, "Run nothing: write sweep.csv (and plots) from the runs in the sweep folder");
  auto* train = cmd->add_flag("--train-only", o->train_only, "Train the sweep's models (with --task, chunk I of N of them); run nothing");
  auto* slurm = cmd->add_flag("--slurm", o->slurm, "Submit the runs to Slurm as an array job, then a job that collects the table");
  slurm->excludes(task)->excludes(collect)->excludes(dry)->excludes(train);
  collect->excludes(task)->excludes(dry)->excludes(train);
  train->excludes(dry);
  auto* group = "Slurm (with --slurm)";
  cmd->add_option("--partition", o->slurm_options.partition, "sbatch --partition")->group(group)->needs(slurm);
  cmd->add_option("--time", o->slurm_options.time, "sbatch --time of each task (e.g. 1:00:00)")->group(group)->needs(slurm);
  cmd->add_option("--tasks", o->slurm_options.tasks, "Array tasks (default: one per run, at most 100)")->check(CLI::Range(1, 100000))->group(group)->needs(slurm);
  cmd->add_option("--cpus-per-task", o->slurm_options.cpus_per_task, "Cores per task: its runs at once (default 1)")
      ->check(CLI::Range(1, 1024))->group(group)->needs(slurm);
  cmd->add_option("--sbatch-arg", o->slurm_options.sbatch_args, "Another #SBATCH line, e.g. --sbatch-arg=--account=lab (repeatable)")
      ->group(group)->needs(slurm);
  cmd->callback([o, &exit_code] { exit_code = tools::Code(RunSweepCommand(*o)); });
}

}  // namespace dyad::cli
