#include "study_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <tuple>
#include <filesystem>
#include <map>
#include <sstream>

#include "bootstrap.hpp"
#include "dyad/mcap/reader.hpp"
#include "study_session.hpp"
#include "build_report.hpp"
#include "text_output.hpp"
#include "yaml_file.hpp"

namespace dyad::study {
namespace {

// A number for people (report.md): six significant digits.
std::string Num(double v) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// A number in a CSV file: exact (a summary recomputed from the rows is the same double).
std::string X(double v) { return tools::CsvNumber(v); }

// The share of a confusion's counts on its diagonal; NaN when it has none.
double Accuracy(const std::vector<std::vector<int64_t>>& m) {
  int64_t all = 0, right = 0;
  for (size_t t = 0; t < m.size(); ++t)
    for (size_t p = 0; p < m[t].size(); ++p) all += m[t][p], right += t == p ? m[t][p] : 0;
  return all > 0 ? static_cast<double>(right) / static_cast<double>(all) : std::nan("");
}

void AddConfusion(const std::vector<std::vector<int64_t>>& m, std::vector<std::vector<int64_t>>* sum) {
  if (m.empty()) return;
  if (sum->size() < m.size()) sum->resize(m.size());
  for (auto& row : *sum) row.resize(std::max(row.size(), m.size()), 0);
  for (size_t t = 0; t < m.size(); ++t)
    for (size_t p = 0; p < m[t].size(); ++p) (*sum)[t][p] += m[t][p];
}

// A condition as the analysis's files name it: by name once unblinded, else by its label only.
std::string NameOf(const StudyAnalysis& a, const Condition& c) { return a.unblinded ? c.name : "condition " + c.label; }

// A primitive as people read it: its name (names.txt), else "primitive K"; -1 is `none`.
std::string PrimitiveName(const StudyAnalysis& a, int k, const char* none) {
  if (k < 0) return none;
  return static_cast<size_t>(k) < a.primitive_names.size() ? a.primitive_names[static_cast<size_t>(k)] : "primitive " + std::to_string(k);
}
std::string Said(const StudyAnalysis& a, int k) { return PrimitiveName(a, k, "something else"); }
std::string Observed(const StudyAnalysis& a, int k) { return PrimitiveName(a, k, "no label"); }

void AddSaid(const SaidVsObserver& m, SaidVsObserver* sum) {
  for (const auto& [key, cell] : m) {
    (*sum)[key].events += cell.events;
    (*sum)[key].steps += cell.steps;
  }
}

std::string TrialsCsv(const Study& s, const StudyAnalysis& a) {
  std::ostringstream out;
  out << "participant,condition,label,trial,repetition,attempt,file,complete,reason";
  for (const std::string& name : TrialMeasures()) out << ',' << name;  // the same names for every trial
  out << '\n';
  for (const TrialResult& r : a.trials) {
    const Condition& c = s.conditions[static_cast<size_t>(r.trial.condition)];
    out << r.participant << ',' << NameOf(a, c) << ',' << c.label << ',' << r.trial.number << ',' << r.trial.repetition << ','
        << r.attempt << ',' << tools::CsvCell(r.trial.file) << ',' << (r.incomplete.empty() ? "true" : "false") << ','
        << tools::CsvCell(r.incomplete);
    for (const auto& [name, value] : r.metrics) out << ',' << X(value);
    out << '\n';
  }
  return out.str();
}

std::string EventsCsv(const Study& s, const StudyAnalysis& a) {
  std::ostringstream out;
  out << "participant,condition,trial,event,start_step,end_step,primitive,self_report,mean_congruence,final_congruence,"
         "human_accuracy,robot_follows,robot_switch_after,complete\n";
  for (const TrialResult& r : a.trials)
    for (const analyze::EventSummary& e : r.events) {
      out << r.participant << ',' << NameOf(a, s.conditions[static_cast<size_t>(r.trial.condition)]) << ',' << r.trial.number << ','
          << e.index << ',' << e.event.start_step << ',' << e.event.end_step << ','
          << (e.event.primitive < 0 ? std::string() : std::to_string(e.event.primitive)) << ','
          << (e.event.reported == analyze::kNotReported ? std::string() : std::to_string(e.event.reported)) << ','
          << X(e.mean_congruence) << ',' << X(e.final_congruence) << ',' << X(e.human_accuracy) << ','
          << X(e.robot_follows) << ',' << (e.robot_switch_after < 0 ? std::string() : std::to_string(e.robot_switch_after))
          << ',' << (r.incomplete.empty() ? "true" : "false") << '\n';
    }
  return out.str();
}

struct ConditionMeasure {
  std::string measure;
  int trials = 0;        // with the measure
  MeanInterval interval;  // over participants: n counts those with the measure
};

// Per condition (in the listing order) and measure: each participant's mean over their counted
// trials of it (trials of one person are not independent), then the mean over participants and
// its bootstrap interval, resampling participants.
using Summaries = std::vector<std::pair<const Condition*, std::vector<ConditionMeasure>>>;
Summaries Summary(const Study& s, const StudyAnalysis& a) {
  Summaries out;
  for (const size_t c : s.ListingOrder()) {
    std::vector<ConditionMeasure> measures;
    for (const std::string& m : SummaryMeasures()) {
      ConditionMeasure cm;
      cm.measure = m;
      std::map<std::string, std::pair<double, int>> by_participant;  // sum, count
      for (const TrialResult& r : a.trials) {
        if (static_cast<size_t>(r.trial.condition) != c || !a.Counted(r)) continue;
        for (const auto& [name, value] : r.metrics)
          if (name == m && !std::isnan(value)) {
            by_participant[r.participant].first += value;
            ++by_participant[r.participant].second;
            ++cm.trials;
          }
      }
      std::vector<double> means;
      for (const auto& [p, sum] : by_participant) means.push_back(sum.first / sum.second);
      cm.interval = BootstrapMean(means, tools::Fnv1a(s.name + "/" + s.conditions[c].name + "/" + m));
      measures.push_back(std::move(cm));
    }
    out.emplace_back(&s.conditions[c], std::move(measures));
  }
  return out;
}

std::string SummaryCsv(const StudyAnalysis& a, const Summaries& summary) {
  std::ostringstream out;
  out << "condition,label,measure,participants,trials,mean,ci_low,ci_high\n";
  for (const auto& [c, measures] : summary)
    for (const ConditionMeasure& m : measures)
      out << NameOf(a, *c) << ',' << c->label << ',' << m.measure << ',' << m.interval.n << ',' << m.trials << ',' << X(m.interval.mean)
          << ',' << X(m.interval.low) << ',' << X(m.interval.high) << '\n';
  return out.str();
}

// A condition as a heading or cell of report.md: "assist (A)" once unblinded, else "condition A".
std::string Heading(const StudyAnalysis& a, const Condition& c) { return a.unblinded ? c.name + " (" + c.label + ")" : NameOf(a, c); }

void IncompleteSection(const StudyAnalysis& a, std::ostream& out) {
  bool any = false;
  for (const TrialResult& r : a.trials) {
    if (r.incomplete.empty()) continue;
    if (!any)
      out << "\n## Incomplete trials\n\n"
          << (a.include_incomplete ? "Counted in the summary (--include-incomplete)."
                                   : "Left out of the summary, summary.csv, the confusion and the plots (--include-incomplete "
                                     "counts them); trials.csv has their rows, `complete` false.")
          << "\n\n";
    any = true;
    out << "- " << r.participant << " trial " << r.trial.number << " (" << r.trial.file << "): " << r.incomplete << "\n";
  }
}

// The self-reports against the observer as a markdown table: a row per answer given (a primitive
// by name, or "something else"), a column per class the observer named; each cell its events,
// their labelled steps in brackets.
void SaidTable(const StudyAnalysis& a, const SaidVsObserver& m, std::ostream& out) {
  std::set<int> said, observed;
  for (const auto& [key, cell] : m) said.insert(key.first), observed.insert(key.second);
  out << "| said / observer |";
  for (const int o : observed) out << ' ' << tools::MarkdownCell(Observed(a, o)) << " |";
  out << "\n|---|";
  for (size_t i = 0; i < observed.size(); ++i) out << "---|";
  out << "\n";
  // "something else" (-1) last: its own row, after the primitives.
  std::vector<int> rows(said.upper_bound(-1), said.end());
  if (said.count(-1)) rows.push_back(-1);
  for (const int r : rows) {
    out << "| **" << tools::MarkdownCell(Said(a, r)) << "** |";
    for (const int o : observed) {
      const auto it = m.find({r, o});
      const SaidCell c = it == m.end() ? SaidCell{} : it->second;
      out << ' ' << c.events << " (" << c.steps << ") |";
    }
    out << "\n";
  }
}

// Per condition: the observer against what the participants said they drew, summed over the
// condition's counted trials, and its accuracy over participants with the interval.
void ReportedConfusionSection(const Study& s, const StudyAnalysis& a, const Summaries& summary, std::ostream& out) {
  if (a.said_vs_observer.empty()) return;
  out << "\n## The observer against the self-reports, per condition\n\n"
         "Rows: what the participant said they drew (\"something else\" its own row); columns: the class the observer "
         "named most over the event's labelled steps; each cell counts events, with the labelled steps of those answers "
         "on which the observer named that class in brackets, over the condition's trials (reported_confusion.csv). "
         "Accuracy: per trial, the share of the labelled steps of events said to be a primitive on which the observer "
         "named it (reported_accuracy), each participant's mean over their trials, then the mean over participants with "
         "its 95% bootstrap interval.\n";
  for (const auto& [c, measures] : summary) {
    const size_t index = static_cast<size_t>(c - s.conditions.data());
    SaidVsObserver m;
    for (const TrialResult& r : a.trials)
      if (static_cast<size_t>(r.trial.condition) == index && a.Counted(r)) AddSaid(r.said_vs_observer, &m);
    out << "\n### " << Heading(a, *c) << "\n\n";
    if (m.empty()) {
      out << "No self-report.\n";
      continue;
    }
    const auto acc =
        std::find_if(measures.begin(), measures.end(), [](const ConditionMeasure& x) { return x.measure == "reported_accuracy"; });
    if (acc == measures.end() || acc->interval.n == 0) {
      out << "Accuracy unknown (no self-report of a primitive with observer labels).\n\n";
    } else {
      const MeanInterval& ci = acc->interval;
      out << "Accuracy " << Num(ci.mean) << " (95% interval " << Num(ci.low) << " to " << Num(ci.high) << "; " << ci.n << " participant"
          << (ci.n == 1 ? "" : "s") << ", " << acc->trials << " trial" << (acc->trials == 1 ? "" : "s") << ").\n\n";
    }
    SaidTable(a, m, out);
  }
}

std::string ReportMd(const Study& s, const StudyAnalysis& a, const Summaries& summary) {
  std::ostringstream out;
  out << "# Study " << s.name << "\n\n" << a.trials.size() << " trial" << (a.trials.size() == 1 ? "" : "s") << " analysed";
  const auto incomplete = std::count_if(a.trials.begin(), a.trials.end(), [](const TrialResult& r) { return !r.incomplete.empty(); });
  if (incomplete > 0)
    out << " (" << incomplete << " incomplete, " << (a.include_incomplete ? "counted: --include-incomplete" : "left out of the summary")
        << "; below)";
  if (!a.missing.empty()) out << ", " << a.missing.size() << " missing (below)";
  out << ". Per condition: each participant's mean over their trials, then the mean over participants and a 95% "
         "bootstrap interval (percentile, resampling participants); \"participants\" and \"trials\" count those that "
         "have the measure.\n\n| condition | measure | participants | trials | mean | 95% interval |\n|---|---|---|---|---|---|\n";
  for (const auto& [c, measures] : summary)
    for (const ConditionMeasure& m : measures) {
      const MeanInterval& ci = m.interval;
      out << "| " << Heading(a, *c) << " | " << m.measure << " | " << ci.n << " | " << m.trials << " | "
          << (ci.n > 0 ? Num(ci.mean) : "unknown") << " | " << (ci.n > 0 ? Num(ci.low) + " to " + Num(ci.high) : "unknown") << " |\n";
    }
  out << "\nmean_congruence: P(C_t), the observer's belief that human and robot intend the same primitive, averaged over "
         "each event, then over events; observer_accuracy: per event, the share of its labelled steps where the observer "
         "names the human's primitive, averaged over events; robot_follows: the same for the robot's intention; "
         "switch_latency_s: from an event's start to the robot's first step on the human's primitive (events where it "
         "switched); nelbo_mean: the deliberator's free energy (negative ELBO) of its window, lower when its model "
         "explains what it perceived; reported_accuracy: the observer against the participant's self-reports (below).\n";
  ReportedConfusionSection(s, a, summary, out);
  IncompleteSection(a, out);
  if (!a.missing.empty()) {
    out << "\n## Missing trials\n\n";
    for (const std::string& m : a.missing) out << "- " << m << "\n";
  }
  if (!a.reports_vs_plan.empty()) {
    int64_t all = 0, wrong = 0;
    for (const auto& [pair, n] : a.reports_vs_plan) all += n, wrong += pair.first != pair.second ? n : 0;
    out << "\n## Self-reports against the plan (synthetic participants)\n\n" << wrong << " of " << all
        << " self-reports name another primitive than the one traced (" << Num(100.0 * static_cast<double>(wrong) / static_cast<double>(all))
        << "%); reports_vs_plan.csv has every pair.\n\n| traced | reported | events |\n|---|---|---|\n";
    for (const auto& [pair, n] : a.reports_vs_plan)
      if (pair.first != pair.second)
        out << "| " << tools::MarkdownCell(Said(a, pair.first)) << " | " << tools::MarkdownCell(Said(a, pair.second)) << " | " << n << " |\n";
  }
  bool any_repeated = false;
  for (const TrialResult& r : a.trials) {
    if (r.repeated.empty()) continue;
    if (!any_repeated) out << "\n## Repeated trials\n\n";
    any_repeated = true;
    out << "- " << r.participant << " trial " << r.trial.number << ": " << r.repeated << "\n";
  }
  if (!a.left_out.empty()) {
    out << "\n## Participants left out\n\n";
    for (const std::string& l : a.left_out) out << "- " << l << "\n";
  }
  if (!a.notes.empty()) {
    out << "\n## The experimenter's notes\n\n| participant | time | during | note |\n|---|---|---|---|\n";
    for (const auto& [p, n] : a.notes)
      out << "| " << p << " | " << n.time << " | " << (n.trial > 0 ? "trial " + std::to_string(n.trial) : "between trials") << " | "
          << tools::MarkdownCell(n.text) << " |\n";
  }
  if (!a.unplanned.empty()) {
    out << "\n## Files not in the plan (not analysed)\n\n";
    for (const std::string& f : a.unplanned) out << "- " << f << "\n";
  }
  return out.str();
}

}  // namespace

std::vector<std::string> TrialMeasures() {
  std::vector<std::string> names;
  for (const auto& [name, value] : analyze::RunMetrics(analyze::Report{})) names.push_back(name);
  names.push_back("reported_accuracy");
  return names;
}

const std::vector<std::string>& SummaryMeasures() {
  static const std::vector<std::string> m = {"mean_congruence", "observer_accuracy", "reported_accuracy", "robot_follows",
                                             "switch_latency_s", "nelbo_mean"};
  return m;
}

std::string EmptyTrialReason(const analyze::Report& r) {
  const auto& missing = r.timeline.missing_topics;
  if (std::find(missing.begin(), missing.end(), "human/input") != missing.end())
    return "no subject: no human input recorded (human/input)";
  if (std::none_of(r.timeline.steps.begin(), r.timeline.steps.end(), [](const analyze::StepSample& x) { return x.engaged; }))
    return kNoEngagedStep;
  return "";
}

SaidVsObserver SaidAgainstObserver(const analyze::Report& r) {
  SaidVsObserver out;
  for (const analyze::EventSummary& e : r.events) {
    if (e.event.reported == analyze::kNotReported) continue;
    std::map<int, int64_t> named;  // the observer's class -> labelled steps
    const auto end = std::min<int64_t>(e.event.end_step, static_cast<int64_t>(r.timeline.steps.size()));
    for (int64_t t = std::max<int64_t>(e.event.start_step, 0); t < end; ++t)
      if (const int k = analyze::MostLikelyClass(r.timeline.steps[static_cast<size_t>(t)].p_human); k >= 0) ++named[k];
    int most = -1;  // the class most steps name, the first on ties; -1: no label
    for (const auto& [k, n] : named)
      if (most < 0 || n > named[most]) most = k;
    ++out[{e.event.reported, most}].events;
    for (const auto& [k, n] : named) out[{e.event.reported, k}].steps += n;
  }
  return out;
}

std::string NotThisTrial(const std::string& file, const Study& study, const std::string& participant, const Trial& trial,
                         bool rehearsal) {
  auto reader = mcap::Reader::Open(file);
  if (!reader.ok()) return reader.status().message();
  const std::map<std::string, std::string>* run = nullptr;
  for (const auto& md : reader->metadata())
    if (md.name == "dyad.run") run = &md.entries;
  if (!run) return "no study metadata (\"dyad.run\"): not recorded by dyad study run";
  auto get = [&](const char* key) {
    const auto it = run->find(key);
    return it == run->end() ? std::string("(none)") : it->second;
  };
  if (get("study") != study.name) return "a recording of study " + get("study") + ", not " + study.name;
  if (get("participant") != participant) return "a recording of participant " + get("participant");
  if (get("trial") != std::to_string(trial.number)) return "a recording of trial " + get("trial");
  const Condition& c = study.conditions[static_cast<size_t>(trial.condition)];
  if (get("condition") != (study.blind ? c.label : c.name))
    return "a recording of condition " + get("condition") + ", which the plan does not give this trial";
  if ((get("rehearsal") == "true") != rehearsal)
    return rehearsal ? "a recording of a participant, not of the rehearsal" : "a rehearsal's recording (synthetic participant)";
  return "";
}

namespace {

// Empty when the file's "dyad.run" metadata says it is attempt `attempt`.
std::string AttemptMismatch(const std::string& file, int attempt) {
  auto reader = mcap::Reader::Open(file);
  if (!reader.ok()) return reader.status().message();
  for (const auto& md : reader->metadata())
    if (md.name == "dyad.run") {
      const auto it = md.entries.find("attempt");
      const std::string said = it == md.entries.end() ? "(none)" : it->second;
      return said == std::to_string(attempt) ? "" : "a recording of attempt " + said + ", not " + std::to_string(attempt);
    }
  return "";
}

// The attempt of `t` to analyse, or the reason there is none (session: the participant's log).
struct Chosen {
  std::string file, why_not, repeated;
  std::string incomplete;  // the session log's reason the attempt was no data (outcome incomplete)
  int attempt = 1;
};
Chosen ChooseAttempt(const Session& session, const Trial& t) {
  Chosen c;
  c.file = t.file;
  const Attempt* done = session.Complete(t.number);
  // None complete, the last whole but nobody took part (outcome incomplete): analysed, and marked.
  if (const Attempt* last = session.Last(t.number); !done && last && last->outcome == AttemptOutcome::kIncomplete) done = last;
  auto add = [&c](const Attempt& a, const std::string& fate) {
    c.repeated += (c.repeated.empty() ? "" : "; ") + ("attempt " + std::to_string(a.attempt) + " " + fate) +
                  (a.reason.empty() ? "" : ", repeated because: " + a.reason);
  };
  for (const Attempt& a : session.attempts) {
    if (a.trial != t.number) continue;
    if (&a == done) add(a, a.outcome == AttemptOutcome::kIncomplete ? "analysed, incomplete: " + a.incomplete : "analysed");
    else
      add(a, a.outcome == AttemptOutcome::kUnended
                 ? "interrupted (the session ended during it)"
                 : std::string(ToString(a.outcome)) + (a.incomplete.empty() ? "" : ": " + a.incomplete));
  }
  if (done) {
    // The plan names the file (the log's path is what it was then: the folder may have moved).
    c.file = AttemptFile(t, done->attempt);
    c.attempt = done->attempt;
    c.incomplete = done->incomplete;
    if (done->attempt == 1 && c.repeated == "attempt 1 analysed") c.repeated.clear();
  } else if (session.Last(t.number)) {
    c.why_not = "incomplete (" + c.repeated + ")";
  }
  return c;
}

}  // namespace

StudyAnalysis AnalyzeStudy(const Study& study, std::ostream& warnings, bool rehearsal, bool include_incomplete) {
  StudyAnalysis a;
  a.include_incomplete = include_incomplete;
  namespace fs = std::filesystem;
  for (const std::string& p : study.participants) {
    const Session session = ReadSession(study, p);
    for (const std::string& problem : session.problems) warnings << "warning: " << problem << "\n";
    if (session.withdrawn) {
      a.left_out.push_back(p + ": withdrew consent" + (session.withdrawn_time.empty() ? "" : " on " + session.withdrawn_time) +
                           (session.data_deleted ? "; their data was deleted" : "; their data is kept but not analysed"));
      continue;
    }
    for (const Note& n : session.notes) a.notes.emplace_back(p, n);
    if (session.excluded) {
      a.left_out.push_back(p + ": excluded: " + session.exclusion_reason);
      continue;
    }
    std::set<std::string> planned;
    for (const Trial& t : study.TrialsOf(p)) {
      for (int k = 1; k <= 99; ++k) planned.insert(fs::path(AttemptFile(t, k)).filename().string());
      const Chosen c = ChooseAttempt(session, t);
      const std::string name = p + " trial " + std::to_string(t.number) + " (" + c.file + ")";
      if (!c.why_not.empty()) {
        a.missing.push_back(name + ": " + c.why_not);
        continue;
      }
      if (!fs::exists(c.file)) {
        a.missing.push_back(name + ": not recorded");
        continue;
      }
      std::string why = NotThisTrial(c.file, study, p, t, rehearsal);
      if (why.empty() && c.attempt > 1) why = AttemptMismatch(c.file, c.attempt);
      if (!why.empty()) {
        a.missing.push_back(name + ": " + why);
        continue;
      }
      auto report = analyze::BuildReport(c.file, warnings);
      if (!report.ok()) {
        a.missing.push_back(name + ": " + report.status().message());
        continue;
      }
      report->planned_s = study.duration_s;  // a trial's recording shorter than planned is incomplete
      TrialResult r;
      r.participant = p;
      r.trial = t;
      r.attempt = c.attempt;
      r.planned = !report->plan.events.empty();
      r.repeated = c.repeated;
      r.metrics = analyze::RunMetrics(*report);
      r.events = report->events;
      r.trial.file = c.file;
      r.incomplete = analyze::IncompleteReason(*report);
      if (r.incomplete.empty()) r.incomplete = EmptyTrialReason(*report);
      if (r.incomplete.empty()) r.incomplete = c.incomplete;  // what the runner saw, when the analysis does not
      r.reported_confusion = report->reported_confusion;
      r.said_vs_observer = SaidAgainstObserver(*report);
      if (a.primitive_names.empty()) a.primitive_names = report->primitive_names;
      r.metrics.emplace_back("reported_accuracy", Accuracy(r.reported_confusion));
      if (a.Counted(r)) {
        if (r.planned)
          for (const analyze::EventSummary& e : r.events)
            if (e.event.primitive >= 0 && e.event.reported != analyze::kNotReported)
              ++a.reports_vs_plan[{e.event.primitive, e.event.reported}];
        AddConfusion(r.reported_confusion, &a.reported_confusion);
        AddSaid(r.said_vs_observer, &a.said_vs_observer);
      }
      a.trials.push_back(std::move(r));
    }
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(fs::path(study.data) / p, ec))
      if (entry.path().extension() == ".mcap" && !planned.count(entry.path().filename().string()))
        a.unplanned.push_back(entry.path().string());
  }
  std::sort(a.unplanned.begin(), a.unplanned.end());
  return a;
}

Status WriteStudyAnalysis(const Study& study, const StudyAnalysis& a, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::IOError(dir, "cannot create the analysis folder: " + ec.message());
  const std::filesystem::path d(dir);
  const Summaries summary = Summary(study, a);  // the bootstrap, once for both files
  const std::pair<const char*, std::string> files[] = {{"trials.csv", TrialsCsv(study, a)},
                                                       {"events.csv", EventsCsv(study, a)},
                                                       {"summary.csv", SummaryCsv(a, summary)},
                                                       {"report.md", ReportMd(study, a, summary)}};
  for (const auto& [name, text] : files)
    if (Status s = tools::WriteTextFile((d / name).string(), text); !s.ok()) return s;
  // The two matrices exist only when there is something in them (an old file goes).
  std::ostringstream confusion, vs_plan;
  confusion << "reported,observer,events,steps\n";
  for (const auto& [key, cell] : a.said_vs_observer)
    confusion << tools::CsvCell(Said(a, key.first)) << ',' << tools::CsvCell(Observed(a, key.second)) << ',' << cell.events << ','
              << cell.steps << '\n';
  vs_plan << "planned,reported,events\n";
  for (const auto& [pair, n] : a.reports_vs_plan)
    vs_plan << tools::CsvCell(Said(a, pair.first)) << ',' << tools::CsvCell(Said(a, pair.second)) << ',' << n << '\n';
  const std::tuple<const char*, bool, std::string> optional[] = {
      {"reported_confusion.csv", !a.said_vs_observer.empty(), confusion.str()},
      {"reports_vs_plan.csv", !a.reports_vs_plan.empty(), vs_plan.str()}};
  for (const auto& [name, present, text] : optional) {
    if (!present) std::filesystem::remove(d / name, ec);
    else if (Status s = tools::WriteTextFile((d / name).string(), text); !s.ok()) return s;
  }
  return Status::OK();
}

}  // namespace dyad::study
