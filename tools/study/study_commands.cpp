#include "study_commands.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include "attempt_end.hpp"
#include "exit_code.hpp"
#include "run_process.hpp"
#include "study_analysis.hpp"
#include "study_file.hpp"
#include "study_links.hpp"
#include "study_page.hpp"
#include "study_serve.hpp"
#include "study_session.hpp"
#include "yaml_file.hpp"

namespace dyad::cli {
namespace {

using tools::ExitCode;
using enum tools::ExitCode;

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
ExitCode Plan(const PlanOptions& o) {
  study::Study s;
  if (!Load(o.file, o.plugins, &s)) return kBadInput;
  const size_t n = s.participants.size();
  std::cout << "study " << s.name << ": " << n << " participant" << (n == 1 ? "" : "s") << " x " << s.conditions.size()
            << " conditions x " << s.trials << " trial" << (s.trials == 1 ? "" : "s") << ", on " << s.graph << "\n";
  std::cout << "order: a balanced Latin square of " << s.square_rows << " rows";
  if (n % static_cast<size_t>(s.square_rows) != 0)
    std::cout << " (" << n << " participants are not a multiple of " << s.square_rows << ": the orders are not balanced)";
  std::cout << "\nconditions" << (s.blind && !o.unblind ? " (blind: --unblind shows what they are)" : "") << ":\n";
  for (const size_t i : s.ListingOrder()) {  // by label when blind
    const study::Condition& c = s.conditions[i];
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

std::string TrialLine(const study::Study& s, const study::Trial& t, size_t of) {
  return "trial " + std::to_string(t.number) + " of " + std::to_string(of) + ": " +
         s.Shown(s.conditions[static_cast<size_t>(t.condition)]);
}

std::string Ended(const study::Attempt& a) {
  char secs[32];
  std::snprintf(secs, sizeof secs, "%.1f s", a.seconds);
  using study::AttemptOutcome;
  if (a.outcome == AttemptOutcome::kComplete) return std::string("complete (") + secs + ")";
  if (a.outcome == AttemptOutcome::kStopped) return std::string("stopped after ") + secs + ": incomplete";
  if (a.outcome == AttemptOutcome::kIncomplete) return std::string("incomplete after ") + secs + ": " + a.incomplete;
  if (a.outcome == AttemptOutcome::kUnended) return "interrupted: the session ended during it";
  return study::FailedLine(a.ended, a.exit, a.seconds);
}

// One line from the experimenter; nothing at the end of input (no answer is never a yes).
std::optional<std::string> Ask(const std::string& prompt) {
  std::cout << prompt << std::flush;
  std::string line;
  if (!std::getline(std::cin, line)) return std::nullopt;
  return line;
}

struct RunOptions {
  std::string file, participant, reason;
  std::vector<std::string> plugins;
  bool consent = false, yes = false, page = false;
  int trial = 0;  // --trial: run this one again (with --reason), then stop
  study::PageOptions page_options;
};

// Consent before the first trial records: how it was given ("" when it is not needed or already
// marked), or nothing when it was not (said). Asked before anything is written.
std::optional<std::string> ConsentGiven(const study::Study& s, const RunOptions& o, const study::Session& before) {
  if (before.withdrawn && !o.consent) {  // a new consent after a withdrawal is never asked for at a prompt
    std::cerr << "dyad study run: " << o.participant << " withdrew consent (" << before.log
              << "): nothing is recorded for them. If they give consent again, --consent marks it\n";
    return std::nullopt;
  }
  if ((!s.consent_required && !before.withdrawn) || before.consent) return std::string();
  if (o.consent) return std::string("--consent");
  if (!o.yes && Ask("Has " + o.participant + " given informed consent? Type yes to mark it: ").value_or("") == "yes")
    return std::string("marked at the prompt");
  std::cerr << "dyad study run: consent is required (consent_required in " << s.file << ") and not marked for " << o.participant
            << ": nothing was recorded (--consent marks it)\n";
  return std::nullopt;
}

// Runs one attempt at `t` and says how it ended (kOk); kBadInput when the plan's order refuses
// it, kFailure when it could not start (both said).
ExitCode RunOne(const study::Study& s, const RunOptions& o, const study::Trial& t, size_t of, const std::string& reason,
                study::Attempt* out) {
  const study::Session session = study::ReadSession(s, o.participant);
  const study::Attempt* last = session.Last(t.number);
  study::AttemptRequest r;
  r.dyad = tools::ThisExecutable();
  r.participant = o.participant;
  r.trial = t;
  r.attempt = last ? last->attempt + 1 : 1;
  while (std::filesystem::exists(study::AttemptFile(t, r.attempt))) ++r.attempt;  // a file the log does not know
  r.reason = reason;
  // The graph's output names what a blind experimenter must not see (its parameters): it goes to
  // a file beside the recording then.
  if (s.blind) r.run_log = std::filesystem::path(study::AttemptFile(t, r.attempt)).replace_extension(".log").string();
  if (std::string why = study::WhyNotStart(session, s.TrialsOf(o.participant), t.number, reason); !why.empty()) {
    std::cerr << "dyad study run: " << why << "\n";
    return kBadInput;
  }
  std::cout << TrialLine(s, t, of) << (r.attempt > 1 ? ", attempt " + std::to_string(r.attempt) : "") << " -> "
            << study::AttemptFile(t, r.attempt) << "\n"
            << (s.self_reports == study::SelfReports::kAfterTrial
                    ? (s.duration_s > 0 ? "  running for " + std::to_string(static_cast<int>(s.duration_s)) + " s"
                                        : std::string("  running until the experimenter's page ends it")) +
                          ", then the subject is asked about each hold and the trial ends once they answer (Ctrl-C stops it)"
                : s.duration_s > 0
                    ? "  running for " + std::to_string(static_cast<int>(s.duration_s)) + " s (Ctrl-C stops it early)"
                    : std::string("  running (Ctrl-C ends it)"))
            << std::endl;
  auto a = study::RunAttempt(s, r);
  if (!a.ok()) {
    std::cerr << "dyad study run: " << a.status().ToString() << "\n";
    return kFailure;
  }
  std::cout << "  trial " << t.number << ": " << Ended(*a) << (r.run_log.empty() ? "" : " (its output: " + r.run_log + ")") << "\n";
  *out = *a;
  return kOk;
}

// The study and the participant, or false after saying what is wrong.
bool LoadParticipant(const std::string& file, const std::vector<std::string>& plugins, const std::string& participant,
                     const char* command, study::Study* s) {
  if (!Load(file, plugins, s)) return false;
  if (s->TrialsOf(participant).empty()) {
    std::cerr << command << ": --participant " << participant << " is not a participant of " << s->file << "\n";
    return false;
  }
  return true;
}

// The participant's session lock, or its reason on stderr. One runner per participant, from the
// first thing that writes (consent, the page) on; a session refused for want of consent leaves
// nothing behind.
StatusOr<study::SessionLock> LockSession(const study::Study& s, const std::string& participant) {
  auto l = study::SessionLock::Acquire(s, participant);
  if (!l.ok()) std::cerr << "dyad study run: " << l.status().ToString() << "\n";
  return l;
}

// `dyad study run --page`: the experimenter's study page instead of the terminal.
ExitCode RunOnPage(const study::Study& s, const RunOptions& o, const study::Session& before) {
  auto held = LockSession(s, o.participant);
  if (!held.ok()) return kBadInput;
  if (Status st = o.consent && !before.consent ? study::MarkConsent(s, o.participant, "--consent") : Status::OK(); !st.ok()) {
    std::cerr << "dyad study run: " << st.ToString() << "\n";
    return kFailure;
  }
  study::PageOptions po = o.page_options;
  po.dyad = tools::ThisExecutable();
  return study::RunStudyPage(s, o.participant, po);
}

// The participant's trials in their order, each not yet complete run; a trial that did not
// complete is run again, with the experimenter's reason, before the next. kOk when every trial is
// complete (said on stdout) or the experimenter stopped at a prompt (q, end of input).
// A session stopped by SIGINT or SIGTERM (the trial under way was stopped and kept as it is):
// what is not complete, and how to go on; 130 as for any run ended by a signal.
ExitCode StoppedBySignal(const study::Study& s, const RunOptions& o, const std::vector<study::Trial>& trials) {
  const study::Session now = study::ReadSession(s, o.participant);
  std::string missing;
  for (const study::Trial& t : trials)
    if (!now.Complete(t.number)) missing += (missing.empty() ? "" : ", ") + std::to_string(t.number);
  std::cerr << "dyad study run: stopped by a signal; " << o.participant << "'s trials not complete: " << missing
            << " (dyad study run again goes on from trial " << missing.substr(0, missing.find(',')) << ")\n";
  return kInterrupted;  // for SIGTERM too: its trial was stopped as by Ctrl-C
}

ExitCode RunInOrder(const study::Study& s, const RunOptions& o, const std::vector<study::Trial>& trials) {
  study::Attempt a;
  auto why_again = [&](const study::Attempt& last) {
    if (o.yes) {
      std::cerr << "dyad study run: trial " << last.trial << " is incomplete (" << Ended(last) << "); repeat it with --trial "
                << last.trial << " --reason TEXT\n";
      return std::string();
    }
    return Ask("Trial " + std::to_string(last.trial) + " was " + Ended(last) + ". Why is it repeated (empty: stop here)? ")
        .value_or("");
  };
  for (const study::Trial& t : trials) {
    const study::Session now = study::ReadSession(s, o.participant);
    if (now.Complete(t.number)) continue;
    std::string reason;
    if (const study::Attempt* last = now.Last(t.number); last && (reason = why_again(*last)).empty()) return kFailure;
    if (!o.yes) {
      const auto answer = Ask(TrialLine(s, t, trials.size()) + ". Enter starts it, q stops here: ");
      if (!answer || *answer == "q") return kOk;  // the end of input starts nothing
    }
    if (ExitCode c = RunOne(s, o, t, trials.size(), reason, &a); c != kOk) return c;
    // With --yes (or Ctrl-C then no reason): stop here, not at the next trial.
    while (a.outcome != study::AttemptOutcome::kComplete) {
      if ((reason = why_again(a)).empty()) return a.interrupted ? StoppedBySignal(s, o, trials) : kFailure;
      if (ExitCode c = RunOne(s, o, t, trials.size(), reason, &a); c != kOk) return c;
    }
  }
  std::cout << o.participant << ": every trial complete (session log " << study::SessionLogPath(s, o.participant) << ")\n";
  return kOk;
}

// `dyad study run`: the participant's trials in their order, from the first not yet complete.
ExitCode RunSession(const RunOptions& o) {
  study::Study s;
  if (!LoadParticipant(o.file, o.plugins, o.participant, "dyad study run", &s)) return kBadInput;
  const std::vector<study::Trial> trials = s.TrialsOf(o.participant);
  if (o.trial > static_cast<int>(trials.size())) {
    std::cerr << "dyad study run: --trial " << o.trial << ": " << o.participant << " has " << trials.size() << " trials\n";
    return kBadInput;
  }
  if (!o.reason.empty() && o.trial == 0) {
    std::cerr << "dyad study run: --reason is the reason of a --trial repetition; give --trial N too\n";
    return kBadInput;
  }
  const study::Session before = study::ReadSession(s, o.participant);
  for (const auto& p : before.problems) std::cerr << "warning: " << p << "\n";
  std::cout << "study " << s.name << ", participant " << o.participant << ": " << trials.size() << " trials\n";
  if (o.page) return RunOnPage(s, o, before);
  const std::optional<std::string> consent = ConsentGiven(s, o, before);
  if (!consent) return kBadInput;
  auto held = LockSession(s, o.participant);
  if (!held.ok()) return kBadInput;
  if (!consent->empty()) {
    if (Status st = study::MarkConsent(s, o.participant, *consent); !st.ok()) {
      std::cerr << "dyad study run: " << st.ToString() << "\n";
      return kFailure;
    }
    std::cout << "consent marked for " << o.participant << " (" << *consent << ")\n";
  }
  if (o.trial > 0) {  // a repetition, asked for on the command line
    if (o.reason.empty()) {
      std::cerr << "dyad study run: --trial " << o.trial << " needs --reason (why the trial is repeated)\n";
      return kBadInput;
    }
    study::Attempt a;
    if (ExitCode c = RunOne(s, o, trials[static_cast<size_t>(o.trial - 1)], trials.size(), o.reason, &a); c != kOk) return c;
    return a.outcome == study::AttemptOutcome::kComplete ? kOk : kFailure;
  }
  return RunInOrder(s, o, trials);
}

struct ParticipantOptions {
  std::string file, participant, text, reason;
  std::vector<std::string> plugins;
  bool delete_data = false, yes = false, include = false;
};


// `dyad study note`: a line in the participant's session log (the study's report lists them).
ExitCode Note(const ParticipantOptions& o) {
  study::Study s;
  if (!LoadParticipant(o.file, o.plugins, o.participant, "dyad study note", &s)) return kBadInput;
  if (Status st = study::AddNote(s, o.participant, o.text); !st.ok()) {
    std::cerr << "dyad study note: " << st.ToString() << "\n";
    return st.code() == Status::Code::kInvalidArgument ? kBadInput : kFailure;
  }
  std::cout << "noted in " << study::SessionLogPath(s, o.participant) << "\n";
  return kOk;
}

// `dyad study exclude` / `include`: the researcher's decision about a participant, with its reason.
ExitCode Exclude(const ParticipantOptions& o) {
  const char* command = o.include ? "dyad study include" : "dyad study exclude";
  study::Study s;
  if (!LoadParticipant(o.file, o.plugins, o.participant, command, &s)) return kBadInput;
  if (Status st = study::ExcludeParticipant(s, o.participant, !o.include, o.reason); !st.ok()) {
    std::cerr << command << ": " << st.ToString() << "\n";
    return st.code() == Status::Code::kInvalidArgument ? kBadInput : kFailure;
  }
  std::cout << o.participant << (o.include ? " is analysed again" : " is left out of the analysis") << " (logged in "
            << study::SessionLogPath(s, o.participant) << "; run dyad study analyze again)\n";
  return kOk;
}

// `dyad study withdraw`: the participant withdraws consent; with --delete-data their files go.
ExitCode Withdraw(const ParticipantOptions& o) {
  study::Study s;
  if (!LoadParticipant(o.file, o.plugins, o.participant, "dyad study withdraw", &s)) return kBadInput;
  auto lock = study::SessionLock::Acquire(s, o.participant);
  if (!lock.ok()) {
    std::cerr << "dyad study withdraw: " << lock.status().ToString() << ": stop the session first\n";
    return kBadInput;
  }
  const std::string folder = (std::filesystem::path(s.data) / o.participant).string();
  if (o.delete_data && !o.yes) {
    const auto answer = Ask("This deletes every file in " + folder + " (recordings, logs, notes) for good. Type delete to go on: ");
    if (answer.value_or("") != "delete") {
      std::cerr << "dyad study withdraw: nothing was done\n";
      return kBadInput;
    }
  }
  auto deleted = study::WithdrawConsent(s, o.participant, o.delete_data, "dyad study withdraw");
  if (!deleted.ok()) {
    std::cerr << "dyad study withdraw: " << deleted.status().ToString() << "\n";
    return kFailure;
  }
  std::cout << o.participant << " withdrew consent: nothing more is recorded for them, and the analysis leaves them out";
  if (o.delete_data) std::cout << "; " << *deleted << " files deleted from " << folder;
  std::cout << "\n";
  // An analysis made before still holds their rows.
  const std::string trials_csv = s.data + "/analysis/trials.csv";
  std::ifstream in(trials_csv);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(o.participant + ",", 0) == 0) {
      std::cout << "warning: " << trials_csv << " still has " << o.participant << "'s rows: run dyad study analyze again\n";
      break;
    }
  return kOk;
}

struct AnalyzeOptions {
  std::string file, out;
  std::vector<std::string> plugins;
  bool rehearsal = false, plots = true, unblind = false, include_incomplete = false;
};

// The analysis of `s` into `dir`, with its plots; false (said) when it could not be written.
bool WriteAnalysis(const study::Study& s, const study::StudyAnalysis& a, const std::string& dir, bool plots,
                   const char* command) {
  if (Status st = study::WriteStudyAnalysis(s, a, dir); !st.ok()) {
    std::cerr << command << ": " << st.ToString() << "\n";
    return false;
  }
  std::vector<std::string> args = {dir};
  if (a.include_incomplete) args.push_back("--include-incomplete");
  if (plots && !a.trials.empty())
    if (tools::ExitStatus rc = tools::RunDyadScript("plot_study.py", args); !rc.ok())
      std::cerr << command << ": warning: the plots were not drawn (python3 with matplotlib; " << rc.ToString() << ")\n";
  return true;
}

// The study as `dyad study rehearse` runs it: its rehearsal graph, recordings in DATA/rehearsal.
study::Study AsRehearsal(study::Study s) {
  s.data = (std::filesystem::path(s.data) / "rehearsal").string();
  return s;
}

// `dyad study rehearse`: every participant's trials, a synthetic human each, then the analysis.
ExitCode Rehearse(const AnalyzeOptions& o) {
  study::Study s;
  if (!Load(o.file, o.plugins, &s)) return kBadInput;
  const study::Study r = AsRehearsal(s);
  int failed = 0, ran = 0;
  for (const std::string& p : r.participants)
    for (const study::Trial& t : r.TrialsOf(p)) {
      const study::Session session = study::ReadSession(r, p);
      if (session.Complete(t.number)) continue;
      const study::Attempt* last = session.Last(t.number);
      study::AttemptRequest req;
      req.dyad = tools::ThisExecutable();
      req.participant = p;
      req.trial = t;
      req.attempt = last ? last->attempt + 1 : 1;
      req.reason = last ? "the rehearsal was resumed" : "";
      req.rehearsal = true;
      // Each synthetic participant and trial its own random streams, the same on every machine.
      req.extra_sets = {"seed=" + std::to_string(tools::Fnv1a(s.name + "/" + p + "/" + std::to_string(t.number)) % 1000000 + 1)};
      req.run_log = std::filesystem::path(study::AttemptFile(t, req.attempt)).replace_extension(".log").string();
      auto lock = study::SessionLock::Acquire(r, p);
      if (!lock.ok()) {
        std::cerr << "dyad study rehearse: " << lock.status().ToString() << "\n";
        return kBadInput;
      }
      auto a = study::RunAttempt(r, req);
      ++ran;
      if (a.ok() && a->interrupted) {
        std::cerr << "dyad study rehearse: interrupted during " << p << " trial " << t.number << " (a new rehearse resumes)\n";
        return kInterrupted;  // as dyad study run and dyad sweep (it exited 1, as for a failure)
      }
      if (!a.ok() || a->outcome != study::AttemptOutcome::kComplete) {
        ++failed;
        std::cerr << p << " " << TrialLine(r, t, r.TrialsOf(p).size()) << ": "
                  << (a.ok() ? Ended(*a) + " (see " + req.run_log + ")" : a.status().ToString()) << "\n";
        continue;
      }
      std::cout << p << " " << TrialLine(r, t, r.TrialsOf(p).size()) << ": " << Ended(*a) << std::endl;
    }
  std::cout << "rehearsal of " << s.name << ": " << ran << " trial" << (ran == 1 ? "" : "s") << " run, " << failed << " failed\n";
  study::StudyAnalysis a = study::AnalyzeStudy(r, std::cerr, true, o.include_incomplete);
  // Rehearsed before anyone comes, seen by the experimenter: a blind study's stays blind.
  a.unblinded = !s.blind || o.unblind;
  const std::string dir = o.out.empty() ? r.data + "/analysis" : o.out;
  if (!WriteAnalysis(r, a, dir, o.plots, "dyad study rehearse")) return kFailure;
  std::cout << "analysis: " << dir << "/report.md (" << a.trials.size() << " trials analysed, " << a.missing.size() << " missing)\n";
  return failed == 0 ? kOk : kFailure;
}

// `dyad study analyze`: every recording of the plan, one table across everyone.
ExitCode Analyze(const AnalyzeOptions& o) {
  study::Study s;
  if (!Load(o.file, o.plugins, &s)) return kBadInput;
  if (o.rehearsal) s = AsRehearsal(s);
  study::StudyAnalysis a = study::AnalyzeStudy(s, std::cerr, o.rehearsal, o.include_incomplete);
  a.unblinded = !s.blind || !o.rehearsal || o.unblind;
  const std::string dir = o.out.empty() ? s.data + "/analysis" : o.out;
  if (!WriteAnalysis(s, a, dir, o.plots, "dyad study analyze")) return kFailure;
  std::cout << "study " << s.name << ": " << a.trials.size() << " trial" << (a.trials.size() == 1 ? "" : "s") << " analysed, "
            << a.missing.size() << " missing";
  int incomplete = 0;
  for (const auto& t : a.trials) incomplete += t.incomplete.empty() ? 0 : 1;
  if (incomplete > 0)
    std::cout << "; " << incomplete << " incomplete, "
              << (a.include_incomplete ? "counted (--include-incomplete)" : "left out of the summary (--include-incomplete counts them)");
  std::cout << "\n";
  for (const auto& m : a.missing) std::cout << "  missing: " << m << "\n";
  for (const auto& t : a.trials)
    if (!t.incomplete.empty())
      std::cout << "  incomplete: " << t.participant << " trial " << t.trial.number << " (" << t.trial.file << "): " << t.incomplete << "\n";
  std::cout << "analysis: " << dir << "/report.md (trials.csv, events.csv, summary.csv, plots/)\n";
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
  plan->callback([o, &exit_code] { exit_code = tools::Code(Plan(*o)); });
  auto a = std::make_shared<AnalyzeOptions>();
  auto* analyze = study->add_subcommand(
      "analyze", "Analyse every recording of a study: one row per trial and per event, per condition a mean with a 95% bootstrap interval");
  analyze->add_option("study", a->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  analyze->add_option("-o,--out", a->out, "Output folder (default: the study's data folder/analysis)");
  analyze->add_option("--plugins", a->plugins, "Extra plugin file or folder (repeatable)");
  analyze->add_flag("!--no-plots", a->plots, "Tables and report only");
  analyze->add_flag("--unblind", a->unblind, "With --rehearsal: name a blind study's conditions (the participants' analysis always does)");
  analyze->add_flag("--include-incomplete", a->include_incomplete,
                    "Count trials whose recording is cut short or shorter than planned in the summary and plots (they are left out)");
  analyze->add_flag("--rehearsal", a->rehearsal, "Analyse the rehearsal's recordings (DATA/rehearsal) instead of the participants'");
  analyze->callback([a, &exit_code] { exit_code = tools::Code(Analyze(*a)); });
  auto r = std::make_shared<RunOptions>();
  auto* run = study->add_subcommand("run", "Run a participant's trials in their planned order, recording each with the study's metadata");
  run->add_option("study", r->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  run->add_option("--participant", r->participant, "The participant's ID (as the study file lists it)")->required();
  run->add_flag("--consent", r->consent, "Mark that the participant has given informed consent (logged)");
  run->add_flag("--yes", r->yes, "Ask nothing: run the remaining trials one after another; stop at one that does not complete");
  run->add_option("--trial", r->trial, "Run this trial again (a new attempt beside the earlier ones), then stop")->check(CLI::Range(1, 9999));
  run->add_option("--reason", r->reason, "Why --trial is repeated (kept in the session log)");
  run->add_option("--plugins", r->plugins, "Extra plugin file or folder (repeatable)");
  auto* page = run->add_flag("--page", r->page, "Run the session from the experimenter's study page (its URL is printed) instead of the terminal");
  run->add_option("--page-port", r->page_options.port, "The study page's port (0: any free one)")->check(CLI::Range(0, 65535))->needs(page);
  run->add_option("--page-port-file", r->page_options.port_file, "Write the study page's port here")->needs(page);
  run->add_option("--subject-port", r->page_options.subject_port, "The subject's port")->check(CLI::Range(0, 65535))->needs(page);
  page->excludes("--yes")->excludes("--trial");
  run->callback([r, &exit_code] { exit_code = tools::Code(RunSession(*r)); });
  auto n = std::make_shared<ParticipantOptions>();
  auto* note = study->add_subcommand("note", "Add a note to a participant's session log (the study's report lists the notes)");
  note->add_option("study", n->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  note->add_option("--participant", n->participant, "The participant's ID")->required();
  note->add_option("text", n->text, "The note")->required();
  note->add_option("--plugins", n->plugins, "Extra plugin file or folder (repeatable)");
  note->callback([n, &exit_code] { exit_code = tools::Code(Note(*n)); });
  for (const bool include : {false, true}) {
    auto e = std::make_shared<ParticipantOptions>();
    e->include = include;
    auto* c = study->add_subcommand(include ? "include" : "exclude",
                                    include ? "Analyse an excluded participant again (logged with the reason)"
                                            : "Leave a participant out of the analysis, with the reason (logged; nothing is deleted)");
    c->add_option("study", e->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
    c->add_option("--participant", e->participant, "The participant's ID")->required();
    c->add_option("--reason", e->reason, "Why (kept in the session log and the report)")->required();
    c->add_option("--plugins", e->plugins, "Extra plugin file or folder (repeatable)");
    c->callback([e, &exit_code] { exit_code = tools::Code(Exclude(*e)); });
  }
  auto w = std::make_shared<ParticipantOptions>();
  auto* withdraw = study->add_subcommand(
      "withdraw", "A participant withdraws consent: nothing more records for them and the analysis leaves them out");
  withdraw->add_option("study", w->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  withdraw->add_option("--participant", w->participant, "The participant's ID")->required();
  withdraw->add_flag("--delete-data", w->delete_data,
                     "Also delete every file of theirs (recordings, logs, notes); the session log keeps one line saying so");
  withdraw->add_flag("--yes", w->yes, "With --delete-data: do not ask");
  withdraw->add_option("--plugins", w->plugins, "Extra plugin file or folder (repeatable)");
  withdraw->callback([w, &exit_code] { exit_code = tools::Code(Withdraw(*w)); });
  auto h = std::make_shared<AnalyzeOptions>();
  auto* rehearse = study->add_subcommand(
      "rehearse", "Run the whole study stepped with synthetic participants (the rehearsal graph), then analyse it, into DATA/rehearsal");
  rehearse->add_option("study", h->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  rehearse->add_option("-o,--out", h->out, "Analysis folder (default: DATA/rehearsal/analysis)");
  rehearse->add_option("--plugins", h->plugins, "Extra plugin file or folder (repeatable)");
  rehearse->add_flag("!--no-plots", h->plots, "Tables and report only");
  rehearse->add_flag("--include-incomplete", h->include_incomplete,
                     "Count trials whose recording is cut short or shorter than planned in the summary and plots");
  rehearse->add_flag("--unblind", h->unblind, "Name a blind study's conditions in the rehearsal's analysis (not for the experimenter's eyes)");
  rehearse->callback([h, &exit_code] { exit_code = tools::Code(Rehearse(*h)); });
  study::AddLinksCommand(study, exit_code);
  study::AddServeCommand(study, exit_code);
}

}  // namespace dyad::cli
