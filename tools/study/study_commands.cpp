#include "study_commands.hpp"

#include <cstdio>
#include <iostream>
#include <memory>

#include "study_analysis.hpp"
#include "study_file.hpp"

namespace dyad::cli {
namespace {

constexpr int kOk = 0, kBadInput = 2;

// The study file, or false after listing its problems.
bool Load(const std::string& file, const std::vector<std::string>& plugins, study::Study* s) {
  std::vector<Diagnostic> problems;
  *s = study::LoadStudy(file, plugins, &problems);
  for (const auto& p : problems) std::cerr << p.ToString() << "\n";
  if (!problems.empty()) std::cerr << file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << "\n";
  return problems.empty();
}

struct PlanOptions {
  std::string file;
  std::vector<std::string> plugins;
  bool unblind = false;
};

// `dyad study plan`: the study checked, and who does which condition when.
int Plan(const PlanOptions& o) {
  study::Study s;
  if (!Load(o.file, o.plugins, &s)) return kBadInput;
  const size_t n = s.participants.size();
  std::cout << "study " << s.name << ": " << n << " participant" << (n == 1 ? "" : "s") << " x " << s.conditions.size()
            << " conditions x " << s.trials << " trial" << (s.trials == 1 ? "" : "s") << ", on " << s.graph << "\n";
  std::cout << "order: a balanced Latin square of " << s.square_rows << " rows";
  if (n % static_cast<size_t>(s.square_rows) != 0)
    std::cout << " (" << n << " participants are not a multiple of " << s.square_rows << ": the orders are not balanced)";
  std::cout << "\nconditions" << (s.blind && !o.unblind ? " (blind: --unblind shows what they are)" : "") << ":\n";
  for (const auto& c : s.conditions) {
    if (s.blind && !o.unblind) {
      std::cout << "  " << s.Shown(c) << "\n";
      continue;
    }
    std::cout << "  " << c.name << (s.blind ? " (condition " + c.label + ")" : "") << ":";
    for (const auto& set : c.sets) std::cout << " " << set;
    std::cout << "\n";
  }
  std::cout << "trials (recordings under " << s.data << "):\n";
  for (const auto& p : s.participants) {
    std::cout << "  " << p << ":";
    for (const auto& t : s.TrialsOf(p)) {
      const auto& c = s.conditions[static_cast<size_t>(t.condition)];
      char nn[16];
      std::snprintf(nn, sizeof nn, "%02d", t.number);
      std::cout << (t.number == 1 ? " " : ", ") << nn << " " << (s.blind && !o.unblind ? c.label : c.name);
    }
    std::cout << "\n";
  }
  return kOk;
}

struct AnalyzeOptions {
  std::string file, out;
  std::vector<std::string> plugins;
};

// `dyad study analyze`: every recording of the plan, one table across everyone.
int Analyze(const AnalyzeOptions& o) {
  study::Study s;
  if (!Load(o.file, o.plugins, &s)) return kBadInput;
  const study::StudyAnalysis a = study::AnalyzeStudy(s, std::cerr);
  const std::string dir = o.out.empty() ? s.data + "/analysis" : o.out;
  if (Status st = study::WriteStudyAnalysis(s, a, dir); !st.ok()) {
    std::cerr << "dyad study analyze: " << st.ToString() << "\n";
    return 1;
  }
  std::cout << "study " << s.name << ": " << a.trials.size() << " trial" << (a.trials.size() == 1 ? "" : "s") << " analysed, "
            << a.missing.size() << " missing\n";
  for (const auto& m : a.missing) std::cout << "  missing: " << m << "\n";
  std::cout << "analysis: " << dir << "/report.md (trials.csv, events.csv, summary.csv)\n";
  return kOk;
}

}  // namespace

void AddStudyCommands(CLI::App& app, int& exit_code) {
  auto* study = app.add_subcommand("study", "A study with people: participants, conditions, trials (docs/study.md)");
  study->require_subcommand(1);
  auto o = std::make_shared<PlanOptions>();
  auto* plan = study->add_subcommand("plan", "Check a study file; print each participant's trials in their counterbalanced order");
  plan->add_option("study", o->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  plan->add_option("--plugins", o->plugins, "Extra plugin file or folder (repeatable)");
  plan->add_flag("--unblind", o->unblind, "Name the conditions of a blind study (not for the experimenter's eyes)");
  plan->callback([o, &exit_code] { exit_code = Plan(*o); });
  auto a = std::make_shared<AnalyzeOptions>();
  auto* analyze = study->add_subcommand(
      "analyze", "Analyse every recording of a study: one row per trial and per event, per condition a mean with a 95% bootstrap interval");
  analyze->add_option("study", a->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  analyze->add_option("-o,--out", a->out, "Output folder (default: the study's data folder/analysis)");
  analyze->add_option("--plugins", a->plugins, "Extra plugin file or folder (repeatable)");
  analyze->callback([a, &exit_code] { exit_code = Analyze(*a); });
}

}  // namespace dyad::cli
