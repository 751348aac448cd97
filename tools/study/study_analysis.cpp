#include "study_analysis.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "bootstrap.hpp"
#include "build_report.hpp"
#include "text_output.hpp"

namespace dyad::study {
namespace {

// FNV-1a: a seed from names that is the same on every machine (std::hash is not).
uint64_t SeedOf(const std::string& text) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
  return h;
}

std::string Num(double v) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

void AddConfusion(const std::vector<std::vector<int64_t>>& m, std::vector<std::vector<int64_t>>* sum) {
  if (m.empty()) return;
  if (sum->size() < m.size()) sum->resize(m.size());
  for (auto& row : *sum) row.resize(std::max(row.size(), m.size()), 0);
  for (size_t t = 0; t < m.size(); ++t)
    for (size_t p = 0; p < m[t].size(); ++p) (*sum)[t][p] += m[t][p];
}

std::string TrialsCsv(const Study& s, const StudyAnalysis& a) {
  std::ostringstream out;
  out << "participant,condition,label,trial,repetition,file";
  for (const auto& [name, value] : analyze::RunMetrics(analyze::Report{})) out << ',' << name;  // the same names for every trial
  out << '\n';
  for (const TrialResult& r : a.trials) {
    const Condition& c = s.conditions[static_cast<size_t>(r.trial.condition)];
    out << r.participant << ',' << c.name << ',' << c.label << ',' << r.trial.number << ',' << r.trial.repetition << ','
        << tools::CsvCell(r.trial.file);
    for (const auto& [name, value] : r.metrics) out << ',' << Num(value);
    out << '\n';
  }
  return out.str();
}

std::string EventsCsv(const Study& s, const StudyAnalysis& a) {
  std::ostringstream out;
  out << "participant,condition,trial,event,start_step,end_step,primitive,self_report,mean_congruence,final_congruence,"
         "human_accuracy,robot_follows,robot_switch_after\n";
  for (const TrialResult& r : a.trials)
    for (const analyze::EventSummary& e : r.events) {
      out << r.participant << ',' << s.conditions[static_cast<size_t>(r.trial.condition)].name << ',' << r.trial.number << ','
          << e.index << ',' << e.event.start_step << ',' << e.event.end_step << ','
          << (e.event.primitive < 0 ? std::string() : std::to_string(e.event.primitive)) << ','
          << (e.event.reported == analyze::kNotReported ? std::string() : std::to_string(e.event.reported)) << ','
          << Num(e.mean_congruence) << ',' << Num(e.final_congruence) << ',' << Num(e.human_accuracy) << ','
          << Num(e.robot_follows) << ',' << (e.robot_switch_after < 0 ? std::string() : std::to_string(e.robot_switch_after))
          << '\n';
    }
  return out.str();
}

struct ConditionMeasure {
  std::string measure;
  int trials = 0;        // with the measure
  MeanInterval interval;  // over participants: n counts those with the measure
};

// Per condition and measure: each participant's mean over their trials of it (trials of one
// person are not independent), then the mean over participants and its bootstrap interval,
// resampling participants.
using Summaries = std::vector<std::pair<const Condition*, std::vector<ConditionMeasure>>>;
Summaries Summary(const Study& s, const StudyAnalysis& a) {
  Summaries out;
  for (size_t c = 0; c < s.conditions.size(); ++c) {
    std::vector<ConditionMeasure> measures;
    for (const std::string& m : SummaryMeasures()) {
      ConditionMeasure cm;
      cm.measure = m;
      std::map<std::string, std::pair<double, int>> by_participant;  // sum, count
      for (const TrialResult& r : a.trials) {
        if (static_cast<size_t>(r.trial.condition) != c) continue;
        for (const auto& [name, value] : r.metrics)
          if (name == m && !std::isnan(value)) {
            by_participant[r.participant].first += value;
            ++by_participant[r.participant].second;
            ++cm.trials;
          }
      }
      std::vector<double> means;
      for (const auto& [p, sum] : by_participant) means.push_back(sum.first / sum.second);
      cm.interval = BootstrapMean(means, SeedOf(s.name + "/" + s.conditions[c].name + "/" + m));
      measures.push_back(std::move(cm));
    }
    out.emplace_back(&s.conditions[c], std::move(measures));
  }
  return out;
}

std::string SummaryCsv(const Summaries& summary) {
  std::ostringstream out;
  out << "condition,label,measure,participants,trials,mean,ci_low,ci_high\n";
  for (const auto& [c, measures] : summary)
    for (const ConditionMeasure& m : measures)
      out << c->name << ',' << c->label << ',' << m.measure << ',' << m.interval.n << ',' << m.trials << ',' << Num(m.interval.mean)
          << ',' << Num(m.interval.low) << ',' << Num(m.interval.high) << '\n';
  return out.str();
}

std::string ReportMd(const Study& s, const StudyAnalysis& a, const Summaries& summary) {
  std::ostringstream out;
  out << "# Study " << s.name << "\n\n" << a.trials.size() << " trial" << (a.trials.size() == 1 ? "" : "s") << " analysed";
  if (!a.missing.empty()) out << ", " << a.missing.size() << " missing (below)";
  out << ". Per condition: each participant's mean over their trials, then the mean over participants and a 95% "
         "bootstrap interval (percentile, resampling participants); \"participants\" and \"trials\" count those that "
         "have the measure.\n\n| condition | measure | participants | trials | mean | 95% interval |\n|---|---|---|---|---|---|\n";
  for (const auto& [c, measures] : summary)
    for (const ConditionMeasure& m : measures) {
      const MeanInterval& ci = m.interval;
      out << "| " << c->name << " (" << c->label << ") | " << m.measure << " | " << ci.n << " | " << m.trials << " | "
          << (ci.n > 0 ? Num(ci.mean) : "unknown") << " | " << (ci.n > 0 ? Num(ci.low) + " to " + Num(ci.high) : "unknown") << " |\n";
    }
  out << "\nmean_congruence: P(C_t), the observer's belief that human and robot intend the same primitive, averaged over "
         "each event, then over events; observer_accuracy: per event, the share of its labelled steps where the observer "
         "names the human's primitive, averaged over events; robot_follows: the same for the robot's intention; "
         "switch_latency_s: from an event's start to the robot's first step on the human's primitive (events where it "
         "switched); nelbo_mean: the deliberator's free energy (negative ELBO) of its window, lower when its model "
         "explains what it perceived.\n";
  if (!a.missing.empty()) {
    out << "\n## Missing trials\n\n";
    for (const std::string& m : a.missing) out << "- " << m << "\n";
  }
  return out.str();
}

}  // namespace

const std::vector<std::string>& SummaryMeasures() {
  static const std::vector<std::string> m = {"mean_congruence", "observer_accuracy", "robot_follows", "switch_latency_s",
                                             "nelbo_mean"};
  return m;
}

StudyAnalysis AnalyzeStudy(const Study& study, std::ostream& warnings) {
  StudyAnalysis a;
  for (const std::string& p : study.participants)
    for (const Trial& t : study.TrialsOf(p)) {
      const std::string name = p + " trial " + std::to_string(t.number) + " (" + t.file + ")";
      if (!std::filesystem::exists(t.file)) {
        a.missing.push_back(name + ": not recorded");
        continue;
      }
      auto report = analyze::BuildReport(t.file, warnings);
      if (!report.ok()) {
        a.missing.push_back(name + ": " + report.status().message());
        continue;
      }
      a.trials.push_back({p, t, analyze::RunMetrics(*report), report->events});
      AddConfusion(report->reported_confusion, &a.reported_confusion);
    }
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
                                                       {"summary.csv", SummaryCsv(summary)},
                                                       {"report.md", ReportMd(study, a, summary)}};
  for (const auto& [name, text] : files)
    if (Status s = tools::WriteTextFile((d / name).string(), text); !s.ok()) return s;
  const std::filesystem::path confusion = d / "reported_confusion.csv";
  if (a.reported_confusion.empty()) {
    std::filesystem::remove(confusion, ec);
    return Status::OK();
  }
  std::ostringstream out;
  out << "reported,predicted,count\n";
  for (size_t t = 0; t < a.reported_confusion.size(); ++t)
    for (size_t p = 0; p < a.reported_confusion[t].size(); ++p) out << t << ',' << p << ',' << a.reported_confusion[t][p] << '\n';
  return tools::WriteTextFile(confusion.string(), out.str());
}

}  // namespace dyad::study
