#include "sweep_runner.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "build_report.hpp"
#include "run_process.hpp"

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

enum class Outcome { kOk, kSkipped, kFailed };

// `dyad analyze --no-plots`, in this process (a second process per run cost a fifth of a short
// run); its warnings go to analyze.log beside the report.
Status Analyze(const std::string& recording, const std::string& report_dir) {
  std::ostringstream warnings;
  auto report = analyze::BuildReport(recording, warnings);
  std::ofstream(fs::path(report_dir).parent_path() / "analyze.log") << warnings.str();
  if (!report.ok()) return report.status();
  return analyze::WriteReport(*report, report_dir);
}

// One run, start to end (see the header).
Outcome DoRun(const SweepPlan& plan, const SweepRun& run, const RunnerOptions& o) {
  const fs::path dir = fs::path(o.out) / "runs" / run.id;
  if (fs::exists(dir / "metrics.json")) return Outcome::kSkipped;
  fs::create_directories(dir);
  fs::remove(dir / "failed.txt");
  std::vector<std::string> run_args = {o.dyad, "run", plan.graph, "--quiet", "--duration", std::to_string(plan.duration_s)};
  for (const auto& s : run.sets) run_args.insert(run_args.end(), {"--set", s});
  run_args.insert(run_args.end(), {"--set", plan.recorder + ".file=" + (dir / "rec.mcap").string()});
  std::string failed;
  if (int rc = tools::RunProcess(run_args, (dir / "run.log").string()); rc != 0) {
    failed = tools::ShellQuoted(run_args) + "\nexited " + std::to_string(rc) + "; the end of run.log:\n" + Tail((dir / "run.log").string(), 20);
  } else if (Status s = Analyze((dir / "rec.mcap").string(), (dir / "report").string()); !s.ok()) {
    failed = "dyad analyze " + (dir / "rec.mcap").string() + ": " + s.message() + "\n";
  } else {
    std::error_code ec;
    fs::copy_file(dir / "report" / "metrics.json", dir / "metrics.json.new", fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(dir / "metrics.json.new", dir / "metrics.json", ec);
    if (ec) failed = "cannot keep the metrics: " + ec.message() + "\n";
  }
  if (failed.empty()) return Outcome::kOk;
  std::ofstream(dir / "failed.txt") << failed;
  return Outcome::kFailed;
}

std::string Duration(double s) {
  char buf[32];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s / 3600), static_cast<int>(s / 60) % 60);
  else std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s / 60), static_cast<int>(s) % 60);
  return buf;
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

RunnerResult RunSweep(const SweepPlan& plan, const RunnerOptions& options, std::ostream& log) {
  RunnerResult result;
  std::atomic<size_t> next{0};
  std::mutex mutex;  // guards result, log, the counts below
  size_t finished = 0, executed = 0;
  const auto t0 = Clock::now();
  auto worker = [&] {
    for (size_t i; (i = next.fetch_add(1)) < plan.runs.size();) {
      const SweepRun& run = plan.runs[i];
      const auto start = Clock::now();
      const Outcome outcome = DoRun(plan, run, options);
      const double secs = std::chrono::duration<double>(Clock::now() - start).count();
      std::lock_guard<std::mutex> lock(mutex);
      ++finished;
      std::string what = "ok";
      if (outcome == Outcome::kSkipped) ++result.skipped, what = "done before";
      else ++executed, ++(outcome == Outcome::kOk ? result.ran : result.failed);
      if (outcome == Outcome::kFailed) what = "FAILED (runs/" + run.id + "/failed.txt)";
      const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
      const size_t left = plan.runs.size() - finished;
      std::string params;
      for (const auto& [k, v] : run.params) params += " " + k + "=" + v;
      log << "[" << finished << "/" << plan.runs.size() << "] " << run.id << params << " seed=" << run.seed << ": " << what;
      if (outcome != Outcome::kSkipped) {
        char s[32];
        std::snprintf(s, sizeof s, " in %.1f s", secs);
        log << s;
      }
      if (left > 0 && executed > 0) log << ", about " << Duration(elapsed / static_cast<double>(executed) * static_cast<double>(left)) << " left";
      log << "\n" << std::flush;
    }
  };
  std::vector<std::thread> threads;
  for (int w = 0; w < std::max(1, options.workers); ++w) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  return result;
}

Status WriteSweepCsv(const SweepPlan& plan, const std::string& out) {
  std::vector<std::string> metric_names;
  std::vector<nlohmann::ordered_json> metrics(plan.runs.size());
  std::vector<std::string> status(plan.runs.size(), "missing");
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const fs::path dir = fs::path(out) / "runs" / plan.runs[i].id;
    std::ifstream in(dir / "metrics.json");
    if (in) {
      metrics[i] = nlohmann::ordered_json::parse(in, nullptr, false);
      if (!metrics[i].is_object()) return Status::DataLoss((dir / "metrics.json").string(), "not a JSON object");
      status[i] = "ok";
      if (metric_names.empty())
        for (const auto& [name, value] : metrics[i].items()) metric_names.push_back(name);
    } else if (fs::exists(dir / "failed.txt")) {
      status[i] = "failed";
    }
  }
  std::ostringstream csv;
  csv << "run,status";
  for (const auto& p : plan.parameters) csv << ',' << CsvField(p);
  csv << ",seed";
  for (const auto& m : metric_names) csv << ',' << CsvField(m);
  csv << '\n';
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const SweepRun& run = plan.runs[i];
    csv << run.id << ',' << status[i];
    for (const auto& p : plan.parameters) {
      std::string v;
      for (const auto& [k, value] : run.params)
        if (k == p) v = value;
      csv << ',' << CsvField(v);
    }
    csv << ',' << run.seed;
    for (const auto& m : metric_names) {
      csv << ',';
      if (metrics[i].is_object() && metrics[i].contains(m) && metrics[i][m].is_number()) {
        std::ostringstream v;
        v.precision(9);
        v << metrics[i][m].get<double>();
        csv << v.str();
      }
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
