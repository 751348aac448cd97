#include "sweep_commands.hpp"

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include "run_process.hpp"
#include "sweep_plan.hpp"
#include "sweep_runner.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;
constexpr int kOk = 0, kFailure = 1, kBadInput = 2;

struct Options {
  std::string file, out;
  int workers = 0;
  std::vector<std::string> plugins;
  bool plots = true, dry_run = false;
};

// <prefix>/share/dyad/plot_sweep.py next to the executable's bin/ (build and installed trees).
std::string Self() {
  std::error_code ec;
  return fs::read_symlink("/proc/self/exe", ec).string();
}

int Plot(const std::string& csv, const std::string& dir) {
  const std::string script = (fs::path(Self()).parent_path().parent_path() / "share" / "dyad" / "plot_sweep.py").string();
  // Debian's interpreter first: python3-matplotlib is installed for it, whatever else is on PATH.
  const std::string python = fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  return tools::RunProcess({python, script, csv, dir});
}

// Back to the folder it started in, whatever happens (the command may run inside a test binary).
struct RestoreCwd {
  std::filesystem::path cwd;
  ~RestoreCwd() {
    std::error_code ec;
    fs::current_path(cwd, ec);
  }
};

int RunSweepCommand(Options o) {
  std::error_code ec;
  const fs::path file = fs::absolute(o.file, ec);
  // Paths in the sweep file (its graph, its set: values) are relative to it, as a graph's are.
  const fs::path cwd = fs::current_path(ec);
  RestoreCwd restore{cwd};
  if (fs::current_path(file.parent_path(), ec); ec) {
    std::cerr << "dyad sweep: " << o.file << ": cannot enter its folder: " << ec.message() << "\n";
    return kBadInput;
  }
  std::vector<Diagnostic> problems;
  const sweep::SweepPlan plan = sweep::LoadSweep(file.string(), o.plugins, &problems);
  if (!problems.empty()) {
    for (const auto& p : problems) std::cerr << p.ToString() << "\n";
    std::cerr << o.file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << ", nothing was run\n";
    return kBadInput;
  }
  const fs::path out = o.out.empty() ? cwd / ("sweep-" + plan.name) : fs::absolute(cwd / o.out);
  const int workers = o.workers > 0 ? o.workers : std::max(1u, std::thread::hardware_concurrency());
  std::cout << "sweep " << plan.name << ": " << plan.runs.size() << " runs of " << plan.graph << " (" << plan.duration_s
            << " s each, stepped), " << workers << " at once, into " << out.string() << "\n";
  if (o.dry_run) {
    for (const auto& r : plan.runs) {
      std::cout << r.id;
      for (const auto& s : r.sets) std::cout << " --set " << s;
      std::cout << "\n";
    }
    return kOk;
  }
  if (fs::create_directories(out / "runs", ec); ec) {
    std::cerr << "dyad sweep: " << out.string() << ": " << ec.message() << "\n";
    return kFailure;
  }
  const sweep::RunnerResult r = sweep::RunSweep(plan, sweep::RunnerOptions{out.string(), workers, Self()}, std::cout);
  if (Status s = sweep::WriteSweepCsv(plan, out.string()); !s.ok()) {
    std::cerr << "dyad sweep: " << s.message() << "\n";
    return kFailure;
  }
  std::cout << "sweep " << plan.name << ": " << r.ran << " ran, " << r.skipped << " done before, " << r.failed
            << " failed; table: " << (out / "sweep.csv").string() << "\n";
  std::cout << std::flush;
  if (o.plots && r.ran + r.skipped > 0) {
    if (int rc = Plot((out / "sweep.csv").string(), (out / "plots").string()); rc != 0)
      std::cerr << "dyad sweep: warning: the plots were not drawn (python3 with matplotlib; exit " << rc << ")\n";
    else
      std::cout << "plots: " << (out / "plots").string() << "/\n";
  }
  return r.failed > 0 ? kFailure : kOk;
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
  cmd->add_flag("--dry-run", o->dry_run, "check the sweep file and list its runs; run nothing");
  cmd->callback([o, &exit_code] { exit_code = RunSweepCommand(*o); });
}

}  // namespace dyad::cli
