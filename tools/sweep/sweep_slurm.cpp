#include "sweep_slurm.hpp"

#include <errno.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "run_process.hpp"

namespace dyad::sweep {
namespace {

namespace fs = std::filesystem;

constexpr int kDefaultMaxTasks = 100;  // one run per task up to here: Slurm schedules them well

bool ParseCount(const std::string& s, int* value) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  *value = std::atoi(s.c_str());
  return true;
}

std::string Slurped(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

// The #SBATCH header both scripts share.
std::string Header(const SweepPlan& plan, const SlurmOptions& o, const std::string& job, const std::string& log) {
  std::string h = "#!/bin/bash\n";
  h += "# Written by `dyad sweep --slurm` for the sweep " + plan.name + " (" + plan.file + "); docs/sweep.md.\n";
  h += "#SBATCH --job-name=" + job + "\n#SBATCH --output=" + log + "\n";
  if (!o.partition.empty()) h += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time.empty()) h += "#SBATCH --time=" + o.time + "\n";
  for (const auto& a : o.sbatch_args) h += "#SBATCH " + a + "\n";
  return h;
}

Status WriteScript(const fs::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::trunc);
  f << text;
  f.close();
  if (!f) return Status::IOError(path.string(), "cannot write");
  fs::permissions(path, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec, fs::perm_options::replace);
  return Status::OK();
}

// `sbatch --parsable ARGS... SCRIPT`: the job's id, or sbatch's own words.
StatusOr<std::string> Sbatch(std::vector<std::string> args, const fs::path& script, const fs::path& said) {
  args.insert(args.begin(), {"sbatch", "--parsable"});
  args.push_back(script.string());
  const tools::ExitStatus rc = tools::RunProcess(args, said.string());
  const std::string out = Slurped(said);
  if (rc.never_started() && rc.error() == ENOENT)
    return Status::FailedPrecondition("sbatch is not on PATH: run --slurm on a machine that submits Slurm jobs (a login node; Debian: slurm-client)");
  if (rc.never_started()) return Status::FailedPrecondition(tools::ShellQuoted(args) + ": " + rc.ToString());
  const std::string id = out.substr(out.find_last_of('\n') + 1);  // sbatch warns on lines before the id
  if (!rc.ok() || id.empty() || id.find_first_not_of("0123456789;_abcdefghijklmnopqrstuvwxyz") != std::string::npos)
    return Status::FailedPrecondition(tools::ShellQuoted(args) + " failed (" +
                                      (rc.exited() ? "exit " + std::to_string(rc.code()) : rc.ToString()) + "): " + out);
  return id.substr(0, id.find(';'));  // "id;cluster" on a federation
}

}  // namespace

Status ParseTask(const std::string& text, TaskSlice* task) {
  const size_t slash = text.find('/');
  TaskSlice t;
  if (slash == std::string::npos || !ParseCount(text.substr(0, slash), &t.index) ||
      !ParseCount(text.substr(slash + 1), &t.count) || t.count < 1 || t.index >= t.count)
    return Status::InvalidArgument("--task " + text, "want I/N with 0 <= I < N (the array task's index, counted from 0, and the number of tasks)");
  *task = t;
  return Status::OK();
}

StatusOr<SlurmJob> SubmitToSlurm(const SweepPlan& plan, const std::string& sweep_file, const std::string& out,
                                 const std::string& dyad, const std::vector<std::string>& plugins, bool plots,
                                 const SlurmOptions& o) {
  const fs::path dir = fs::path(out) / "slurm";
  std::error_code ec;
  if (fs::create_directories(dir, ec); ec) return Status::IOError(dir.string(), ec.message());
  std::vector<std::string> plugin_args;
  for (const auto& p : plugins) plugin_args.insert(plugin_args.end(), {"--plugins", p});
  // An array of `dyad sweep SWEEP --task $SLURM_ARRAY_TASK_ID/N ARGS...`.
  auto array_script = [&](const std::string& job, const std::string& log, int tasks, const std::string& what,
                          std::vector<std::string> args) {
    args.insert(args.end(), plugin_args.begin(), plugin_args.end());
    return Header(plan, o, job, (dir / log).string()) + "#SBATCH --array=0-" + std::to_string(tasks - 1) +
           "\n#SBATCH --cpus-per-task=" + std::to_string(o.cpus_per_task) + "\n# " + what + "\nexec " +
           tools::ShellQuoted({dyad, "sweep", sweep_file}) + " --task \"$SLURM_ARRAY_TASK_ID/" + std::to_string(tasks) +
           "\" -j \"${SLURM_CPUS_PER_TASK:-1}\" " + tools::ShellQuoted(args) + "\n";
  };
  SlurmJob job;
  bool train = false;
  for (const auto& t : plan.trainings) train = train || !fs::exists(ModelPath(out, t));
  if (train) {
    job.train_tasks = std::min(static_cast<int>(plan.trainings.size()), kDefaultMaxTasks);
    const std::string what = std::to_string(plan.trainings.size()) + " models in " + std::to_string(job.train_tasks) +
                             " tasks; a task skips a model that is there.";
    if (Status s = WriteScript(dir / "train.sbatch", array_script("dyad-sweep-" + plan.name + "-train", "train-%a.log",
                                                                  job.train_tasks, what, {"-o", out, "--train-only"}));
        !s.ok())
      return s;
  }
  const int runs = static_cast<int>(plan.runs.size());
  job.tasks = std::max(1, std::min(runs, o.tasks > 0 ? o.tasks : kDefaultMaxTasks));
  const std::string what = std::to_string(runs) + " runs in " + std::to_string(job.tasks) + " tasks; a task skips its runs that finished before.";
  std::vector<std::string> collect_args = {dyad, "sweep", sweep_file, "--collect", "-o", out};
  collect_args.insert(collect_args.end(), plugin_args.begin(), plugin_args.end());
  if (!plots) collect_args.push_back("--no-plots");
  if (Status s = WriteScript(dir / "runs.sbatch", array_script("dyad-sweep-" + plan.name, "task-%a.log", job.tasks, what,
                                                               {"-o", out, "--no-plots"}));
      !s.ok())
    return s;
  if (Status s = WriteScript(dir / "collect.sbatch", Header(plan, o, "dyad-sweep-" + plan.name + "-collect", (dir / "collect.log").string()) +
                                                         "exec " + tools::ShellQuoted(collect_args) + "\n");
      !s.ok())
    return s;

  if (train) {
    auto id = Sbatch({}, dir / "train.sbatch", dir / "sbatch.out");
    if (!id.ok()) return id.status();
    job.train_id = *id;
  }
  auto array_id = Sbatch(train ? std::vector<std::string>{"--dependency=afterany:" + job.train_id} : std::vector<std::string>{},
                         dir / "runs.sbatch", dir / "sbatch.out");
  if (!array_id.ok()) {
    if (!train) return array_id.status();
    return Status::FailedPrecondition("the trainings were submitted (job " + job.train_id + ") but not the runs: " +
                                      array_id.status().message() + "; submit again once they have ended (the models are kept)");
  }
  job.array_id = *array_id;
  auto collect_id = Sbatch({"--dependency=afterany:" + job.array_id}, dir / "collect.sbatch", dir / "sbatch.out");
  if (!collect_id.ok())
    return Status::FailedPrecondition("the runs were submitted (job " + job.array_id + ") but not their collection: " +
                                      collect_id.status().message() + "; run `dyad sweep " + sweep_file + " --collect -o " + out +
                                      "` once they have ended");
  job.collect_id = *collect_id;
  return job;
}

}  // namespace dyad::sweep
