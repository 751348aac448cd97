#include "report_writer.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <tuple>

#include "text_output.hpp"

namespace dyad::analyze {
namespace {

std::string Num(double v, int precision = 3) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(precision);
  s << v;
  return s.str();
}

// A number in a CSV file: exact (tools::CsvNumber).
std::string X(double v) { return tools::CsvNumber(v); }

std::string EventsCsv(const Report& r) {
  std::ostringstream s;
  s << "event,start_step,end_step,primitive,mean_congruence,final_congruence,human_accuracy,robot_follows,"
       "robot_switch_after,self_report\n";
  for (const EventSummary& e : r.events) {
    s << e.index << ',' << e.event.start_step << ',' << e.event.end_step << ',' << e.event.primitive << ','
      << X(e.mean_congruence) << ',' << X(e.final_congruence) << ',' << X(e.human_accuracy) << ','
      << X(e.robot_follows) << ',' << e.robot_switch_after << ','
      << (e.event.reported == kNotReported ? std::string() : std::to_string(e.event.reported)) << '\n';
  }
  return s.str();
}

// `truth`: the first column's name ("true": the traced primitive; "reported": the self-report).
std::string ConfusionCsv(const std::vector<std::vector<int64_t>>& m, const char* truth) {
  std::ostringstream s;
  s << truth << ",predicted,count\n";
  for (size_t t = 0; t < m.size(); ++t) {
    for (size_t p = 0; p < m[t].size(); ++p) s << t << ',' << p << ',' << m[t][p] << '\n';
  }
  return s.str();
}

std::string TimelineCsv(const Report& r) {
  std::ostringstream s;
  s << "step,time_s,human_x,human_y,engaged,robot_x,robot_y,executed_x,executed_y,nelbo,reconstruction,"
       "regulation,optimisation_s,congruence,human_class,robot_class\n";
  for (const StepSample& x : r.timeline.steps) {
    // step * period in ns, divided once: 0.3, not 3 * 0.1 = 0.30000000000000004.
    s << x.step << ',' << X(static_cast<double>(x.step * r.plan.period_ns) / 1e9) << ',' << X(x.human_x) << ','
      << X(x.human_y) << ',' << (x.engaged ? 1 : 0) << ',' << X(x.robot_x) << ',' << X(x.robot_y)
      << ',' << X(x.executed_x) << ',' << X(x.executed_y) << ',' << X(x.nelbo) << ','
      << X(x.reconstruction) << ',' << X(x.regulation) << ',' << X(x.optimisation_s) << ','
      << X(x.congruence) << ',' << MostLikelyClass(x.p_human) << ',' << MostLikelyClass(x.p_robot) << '\n';
  }
  return s.str();
}

std::string ParamsCsv(const Report& r) {
  std::ostringstream s;
  s << "step,time_s,component,param,old_value,value,who\n";
  for (const ParamChangeEvent& c : r.param_changes) {
    s << c.step << ',' << X(c.time_s) << ',' << tools::CsvCell(c.component) << ',' << tools::CsvCell(c.param) << ','
      << tools::CsvCell(c.old_value) << ',' << tools::CsvCell(c.value) << ',' << tools::CsvCell(c.who) << '\n';
  }
  return s.str();
}

void ParamChangesSection(const Report& r, std::ostream& s) {
  if (r.param_changes.empty()) return;
  s << "\n## Live parameter changes\n\n";
  s << "| time | component.param | old -> new | who |\n|---|---|---|---|\n";
  for (const ParamChangeEvent& c : r.param_changes) {
    s << "| " << Num(c.time_s, 3) << " s (step " << c.step << ") | " << tools::MarkdownCell(c.component + "." + c.param) << " | "
      << tools::MarkdownCell(c.old_value) << " -> " << tools::MarkdownCell(c.value) << " | " << tools::MarkdownCell(c.who) << " |\n";
  }
  s << "\nEach change was applied at the component's step boundary (between two of its steps, never mid-step): "
       "its steps from then on used the new value (params.csv).\n";
}

std::string NotesCsv(const Report& r) {
  std::ostringstream s;
  s << "step,time_s,author,text\n";
  for (const NoteEvent& n : r.notes)
    s << n.step << ',' << X(n.time_s) << ',' << tools::CsvCell(n.author) << ',' << tools::CsvCell(n.text) << '\n';
  return s.str();
}

void NotesSection(const Report& r, std::ostream& s) {
  if (r.notes.empty()) return;
  s << "\n## The experimenter's notes\n\n| time | who | note |\n|---|---|---|\n";
  for (const NoteEvent& n : r.notes)
    s << "| " << Num(n.time_s, 3) << " s (step " << n.step << ") | " << tools::MarkdownCell(n.author) << " | "
      << tools::MarkdownCell(n.text) << " |\n";
  s << "\nThe plots mark each note at its time (notes.csv).\n";
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(std::min<double>(v.size() - 1, std::floor(q * static_cast<double>(v.size()))))];
}

// Mean of the finite values; NaN when none.
double FiniteMean(const std::vector<double>& v) {
  double sum = 0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) sum += x, ++n;
  return n > 0 ? sum / n : std::nan("");
}

// {"name": value, ...} in RunMetrics' order; NaN (no value) as null.
std::string MetricsJson(const Report& r) {
  std::ostringstream s;
  s << "{";
  bool first = true;
  for (const auto& [name, value] : RunMetrics(r)) {
    s << (first ? "\n  " : ",\n  ") << '"' << name << "\": ";
    if (std::isfinite(value)) {
      s << X(value);  // exact: sweep.csv copies it
    } else {
      s << "null";
    }
    first = false;
  }
  s << "\n}\n";
  return s.str();
}

// The run's header and the bullets that summarise it.
void SummarySection(const Report& r, std::ostream& s) {
  s << "# Experiment report\n\n";
  // First, before any number: a cut-short or short recording is not the run it claims to be.
  if (const std::string why = IncompleteReason(r); !why.empty())
    s << "**Incomplete recording: " << tools::MarkdownCell(why) << ".** Every number below is of what it holds; "
      << "`dyad study analyze` and `dyad sweep` leave such a run out of their summaries.\n\n";
  s << "- recording: `" << r.recording << "`\n";
  if (!r.plan.graph_name.empty()) s << "- graph: `" << r.plan.graph_name << "`\n";
  s << "- steps: " << r.timeline.steps.size() << " of " << Num(static_cast<double>(r.plan.period_ns) * 1e-6, 1)
    << " ms\n";
  if (!r.timeline.clock_corrections_ns.empty()) {
    s << "- stamps moved onto the clock of the recorder's process `" << r.plan.recorder_process
      << "` (offsets it measured, dyad/clock_offsets):";
    for (const auto& [process, ns] : r.timeline.clock_corrections_ns)
      s << " `" << process << "` " << (ns >= 0 ? "+" : "") << Num(static_cast<double>(ns) * 1e-6, 3) << " ms";
    s << "\n";
  }
  if (!r.timeline.missing_topics.empty()) {
    s << "- missing topics (their columns are empty):";
    for (const std::string& t : r.timeline.missing_topics) s << " `" << t << "`";
    s << "\n";
  }
  std::vector<double> opt_ms, c_engaged, c_free, nelbo;
  int64_t engaged_steps = 0;
  for (const StepSample& x : r.timeline.steps) {
    engaged_steps += x.engaged;
    if (!std::isnan(x.optimisation_s)) opt_ms.push_back(x.optimisation_s * 1e3);
    if (!std::isnan(x.nelbo)) nelbo.push_back(x.nelbo);
    // The idle time before the first engagement (a participant settling in) is no part of the
    // interaction: the disengaged mean starts with the first engagement.
    if (!std::isnan(x.congruence) && engaged_steps > 0) (x.engaged ? c_engaged : c_free).push_back(x.congruence);
  }
  auto mean = [](const std::vector<double>& v) {
    double t = 0;
    for (double x : v) t += x;
    return v.empty() ? std::nan("") : t / static_cast<double>(v.size());
  };
  s << "- engaged steps: " << engaged_steps << "\n";
  if (nelbo.empty()) s << "- N-ELBO: not recorded (no robot/intention samples)\n";
  else s << "- N-ELBO: mean " << Num(mean(nelbo)) << ", median " << Num(Percentile(nelbo, 0.5)) << "\n";
  if (opt_ms.empty()) s << "- deliberation time per step: not recorded\n";
  else s << "- deliberation time per step: median " << Num(Percentile(opt_ms, 0.5)) << " ms, p99 "
         << Num(Percentile(opt_ms, 0.99)) << " ms, max " << Num(Percentile(opt_ms, 1.0)) << " ms\n";
  const double free = mean(c_free);
  const double engaged = mean(c_engaged);
  s << "- congruence P(C_t): "
    << (engaged_steps == 0       ? std::string("never engaged, so not measured while engaged")
        : std::isnan(engaged)    ? std::string("not measured while engaged (no observer labels)")
                                 : "mean " + Num(engaged) + " while engaged")
    << ", " << (std::isnan(free) ? std::string("not measured") : Num(free)) << " otherwise (from the first engagement on)\n";
  s << "\nN-ELBO is the deliberator's free energy over its window of what it perceived (how badly its "
       "model's reconstruction fits, plus how far its posterior moved from its prior): lower means its "
       "model explains what happened. P(C_t), the congruence, is the observer's probability at step t that "
       "the human and the robot intend the same primitive.\n";

  if (r.plan.events.size() > r.events.size()) {
    const size_t n = r.plan.events.size() - r.events.size();
    s << "- " << n << " planned event" << (n == 1 ? "" : "s") << " after the end of the recording (not scored)\n";
  }
  // A partition or a stalled writer shows here, before the tables whose numbers it would skew
  // (after the bullets: a heading between them put the last bullets under it).
  if (!r.transport.empty()) s << "\n## Transport: what the recording lost, what the runtime healed\n\n```\n" << r.transport << "```\n";
}

// A primitive by its data set's name when it has one: "heart (5)", else "5".
std::string Primitive(const Report& r, int k) {
  return static_cast<size_t>(k) < r.primitive_names.size() ? r.primitive_names[static_cast<size_t>(k)] + " (" + std::to_string(k) + ")"
                                                           : std::to_string(k);
}

// The event's primitive, and what the person said when it differs: "3", "3 (said 5)",
// "3 (said: something else)"; "unknown" when neither the plan nor a self-report names it.
std::string PrimitiveCell(const Report& r, const PlannedEvent& e) {
  std::string cell = e.primitive < 0 ? std::string("unknown") : Primitive(r, e.primitive);
  if (e.reported == -1) cell += " (said: something else)";
  else if (e.reported >= 0 && e.reported != e.primitive) cell += " (said " + Primitive(r, e.reported) + ")";
  return cell;
}

// A measure against the event's primitive: "unknown" when nobody knows what the human traced.
std::string OrUnknown(const EventSummary& e, double v) { return e.event.primitive < 0 ? std::string("unknown") : Num(v); }

void EventsSection(const Report& r, std::ostream& s) {
  s << "\n## Events\n\n";
  if (r.practice_events > 0)
    s << r.practice_events << " event(s) started while the subject's page said \"practice\" (subject/task) and are left out of "
      << "everything below.\n\n";
  if (r.events.empty()) {
    s << "No interventions (the human never engaged).\n\n";
  } else {
    s << "| event | steps (first-last) | primitive | mean P(C) | final P(C) | observer on human | robot follows | robot switched after |\n";
    s << "|---|---|---|---|---|---|---|---|\n";
    for (const EventSummary& e : r.events) {
      // An event the recording ends inside is scored over its recorded steps: say so.
      std::string cut;
      for (const PlannedEvent& p : r.plan.events)
        if (p.start_step == e.event.start_step && p.end_step > e.event.end_step)
          cut = " (cut off by the end of the recording; planned to " + std::to_string(p.end_step - 1) + ")";
      s << "| " << e.index << " | " << e.event.start_step << "-" << e.event.end_step - 1 << cut << " | "
        << tools::MarkdownCell(PrimitiveCell(r, e.event)) << " | "
        << Num(e.mean_congruence) << " | " << Num(e.final_congruence) << " | " << OrUnknown(e, e.human_accuracy) << " | "
        << OrUnknown(e, e.robot_follows) << " | "
        << (e.event.primitive < 0        ? std::string("unknown")
            : e.robot_switch_after < 0   ? std::string("never")
                                         : std::to_string(e.robot_switch_after) + " steps")
        << " |\n";
    }
    s << "\n\"observer on human\": fraction of the event's steps where the observer's most likely class of the "
         "human's motion is the primitive the human traced; \"robot follows\": the same for the robot's intention; "
         "\"robot switched after\": steps from the event's start to the first step where the robot's intention is "
         "classified as the human's primitive (\"never\": not within the event; \"unknown\": the human's primitive is not "
         "known, neither planned nor said).\n\n";
  }
}

// A row-normalised confusion matrix as a markdown table (rows with no count left out), the rows
// by name when the data set names its primitives.
void ConfusionTable(const Report& r, const std::vector<std::vector<int64_t>>& m, std::ostream& s) {
  s << "|   |";
  for (size_t p = 0; p < m.size(); ++p) s << ' ' << p << " |";
  s << "\n|---|";
  for (size_t p = 0; p < m.size(); ++p) s << "---|";
  s << "\n";
  for (size_t t = 0; t < m.size(); ++t) {
    int64_t total = 0;
    for (int64_t c : m[t]) total += c;
    if (total == 0) continue;
    s << "| **" << tools::MarkdownCell(Primitive(r, static_cast<int>(t))) << "** |";
    for (int64_t c : m[t]) s << ' ' << Num(static_cast<double>(c) / static_cast<double>(total), 2) << " |";
    s << "\n";
  }
}

void ConfusionSection(const Report& r, std::ostream& s) {
  s << "## Observer confusion on the human's traces\n\n";
  if (r.confusion.empty()) {
    s << "Not available: the recording has no observer labels during events with a known primitive.\n";
  } else {
    s << "Rows: primitive the human traced; columns: the observer's most likely class; row-normalised "
         "(counts in confusion.csv).\n\n";
    ConfusionTable(r, r.confusion, s);
  }
  if (r.reported_confusion.empty()) return;
  s << "\n## Observer confusion against the self-reports\n\n"
       "Rows: the primitive the person said they drew when they released; columns: the observer's most likely "
       "class over that event's steps; row-normalised (counts in reported_confusion.csv).\n\n";
  ConfusionTable(r, r.reported_confusion, s);
}

}  // namespace

std::string IncompleteReason(const Report& r) {
  if (!r.incomplete.empty()) return r.incomplete;
  if (!(r.planned_s > 0)) return "";
  const double period_s = static_cast<double>(r.plan.period_ns) / 1e9;
  if (r.timeline.steps.empty()) {  // no experiment steps: the messages' span measures the run
    const double recorded_s = r.message_span_s >= 0 ? r.message_span_s + period_s : 0;
    if (recorded_s >= 0.95 * r.planned_s) return "";
    if (r.message_span_s < 0) return "shorter than planned: no message recorded of the " + tools::CsvNumber(r.planned_s) + " s planned";
    return "shorter than planned: messages over " + tools::CsvNumber(r.message_span_s) + " s (no experiment steps) of the " +
           tools::CsvNumber(r.planned_s) + " s planned";
  }
  const double recorded_s = static_cast<double>(static_cast<int64_t>(r.timeline.steps.size()) * r.plan.period_ns) / 1e9;
  if (recorded_s >= 0.95 * r.planned_s) return "";
  return "shorter than planned: " + std::to_string(r.timeline.steps.size()) + " steps of " +
         tools::CsvNumber(static_cast<double>(r.plan.period_ns) / 1e6) + " ms (" + tools::CsvNumber(recorded_s) + " s) of the " +
         tools::CsvNumber(r.planned_s) + " s planned";
}

std::vector<std::pair<std::string, double>> RunMetrics(const Report& r) {
  std::vector<double> congruence, final_congruence, accuracy, follows, switch_s, switched, nelbo;
  const double period_s = static_cast<double>(r.plan.period_ns) * 1e-9;
  for (const EventSummary& e : r.events) {
    congruence.push_back(e.mean_congruence);
    final_congruence.push_back(e.final_congruence);
    accuracy.push_back(e.human_accuracy);
    follows.push_back(e.robot_follows);
    switched.push_back(e.robot_switch_after >= 0 ? 1.0 : 0.0);
    if (e.robot_switch_after >= 0) switch_s.push_back(static_cast<double>(e.robot_switch_after) * period_s);
  }
  int64_t engaged = 0;
  for (const StepSample& x : r.timeline.steps) {
    nelbo.push_back(x.nelbo);
    engaged += x.engaged ? 1 : 0;
  }
  const double steps = static_cast<double>(r.timeline.steps.size());
  return {{"steps", steps},
          {"engaged_fraction", steps > 0 ? static_cast<double>(engaged) / steps : std::nan("")},
          {"events", static_cast<double>(r.events.size())},
          {"mean_congruence", FiniteMean(congruence)},
          {"final_congruence", FiniteMean(final_congruence)},
          {"observer_accuracy", FiniteMean(accuracy)},
          {"robot_follows", FiniteMean(follows)},
          {"switched_fraction", FiniteMean(switched)},
          {"switch_latency_s", FiniteMean(switch_s)},
          {"nelbo_mean", FiniteMean(nelbo)}};
}

std::string FormatMarkdown(const Report& r) {
  std::ostringstream s;
  SummarySection(r, s);
  // Before the scores: a change of a parameter during the run may explain them.
  ParamChangesSection(r, s);
  NotesSection(r, s);
  EventsSection(r, s);
  ConfusionSection(r, s);
  s << "\n## Plots\n\n![workspace](workspace.png)\n\n![N-ELBO](nelbo.png)\n\n![congruence](congruence.png)\n";
  return s.str();
}

Status WriteReport(const Report& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::IOError(dir, "cannot create the report folder: " + ec.message());
  const std::pair<const char*, std::string> files[] = {
      {"report.md", FormatMarkdown(r)}, {"events.csv", EventsCsv(r)},     {"confusion.csv", ConfusionCsv(r.confusion, "true")},
      {"timeline.csv", TimelineCsv(r)}, {"graph.yaml", r.graph_yaml},    {"metrics.json", MetricsJson(r)},
  };
  for (const auto& [name, text] : files) {
    if (Status s = tools::WriteTextFile(dir + "/" + name, text); !s.ok()) return s;
  }
  const std::string reported = dir + "/reported_confusion.csv";  // as params.csv below: no stale one
  if (!r.reported_confusion.empty()) {
    if (Status s = tools::WriteTextFile(reported, ConfusionCsv(r.reported_confusion, "reported")); !s.ok()) return s;
  } else {
    std::filesystem::remove(reported, ec);
  }
  // The plots draw whatever params.csv and notes.csv the folder holds, and a sweep's table reads
  // incomplete.txt: an earlier report's must go.
  const std::string incomplete = IncompleteReason(r);
  const std::tuple<std::string, bool, std::string> marked[] = {{dir + "/params.csv", !r.param_changes.empty(), ParamsCsv(r)},
                                                               {dir + "/notes.csv", !r.notes.empty(), NotesCsv(r)},
                                                               {dir + "/incomplete.txt", !incomplete.empty(), incomplete + "\n"}};
  for (const auto& [path, present, text] : marked) {
    if (present) {
      if (Status s = tools::WriteTextFile(path, text); !s.ok()) return s;
      continue;
    }
    std::filesystem::remove(path, ec);
    if (ec) return Status::IOError(path, "cannot remove the previous report's: " + ec.message());
  }
  return Status::OK();
}

}  // namespace dyad::analyze
