#include "study_commands.hpp"

#include <cstdio>
#include <iostream>
#include <memory>

#include "study_file.hpp"

namespace dyad::cli {
namespace {

constexpr int kOk = 0, kBadInput = 2;

struct PlanOptions {
  std::string file;
  std::vector<std::string> plugins;
  bool unblind = false;
};

// `dyad study plan`: the study checked, and who does which condition when.
int Plan(const PlanOptions& o) {
  std::vector<Diagnostic> problems;
  const study::Study s = study::LoadStudy(o.file, o.plugins, &problems);
  if (!problems.empty()) {
    for (const auto& p : problems) std::cerr << p.ToString() << "\n";
    std::cerr << o.file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << "\n";
    return kBadInput;
  }
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
}

}  // namespace dyad::cli
