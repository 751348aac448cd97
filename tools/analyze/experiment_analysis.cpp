#include "experiment_analysis.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace dyad::analyze {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

StepSample EmptyStep(int64_t step) {
  StepSample s;
  s.step = step;
  s.human_x = s.human_y = s.robot_x = s.robot_y = s.nelbo = s.reconstruction = s.regulation = kNaN;
  s.optimisation_s = s.executed_x = s.executed_y = s.congruence = kNaN;
  return s;
}

// Reads a table's cells by column name; a missing column is a clear DataLoss.
class Cells {
 public:
  Cells(const std::string& topic, const TopicTable& table) : topic_(topic), table_(table) {}
  Status Need(const std::vector<std::string>& names) {
    for (const std::string& n : names) {
      const int c = table_.Column(n);
      if (c < 0) return Status::DataLoss("topic " + topic_, "has no field \"" + n + "\"");
      index_[n] = c;
    }
    return Status::OK();
  }
  StatusOr<double> Number(size_t row, const std::string& name) const {
    double v = 0;
    const std::string& cell = table_.rows[row][index_.at(name)];
    if (!ParseNumber(cell, &v)) return Bad(row, name, cell);
    return v;
  }
  StatusOr<bool> Bool(size_t row, const std::string& name) const {
    bool v = false;
    const std::string& cell = table_.rows[row][index_.at(name)];
    if (!ParseBool(cell, &v)) return Bad(row, name, cell);
    return v;
  }
  const std::string& Text(size_t row, const std::string& name) const { return table_.rows[row][index_.at(name)]; }
  Status List(size_t row, const std::string& name, std::vector<double>* out) const {
    const std::string& cell = table_.rows[row][index_.at(name)];
    if (!ParseNumberList(cell, out)) return Bad(row, name, cell);
    return Status::OK();
  }

 private:
  Status Bad(size_t row, const std::string& name, const std::string& cell) const {
    return Status::DataLoss("topic " + topic_ + " message " + std::to_string(row + 1),
                            "field \"" + name + "\" holds \"" + cell + "\"");
  }
  std::string topic_;
  const TopicTable& table_;
  std::map<std::string, int> index_;
};

const char* const kTimelineTopics[] = {"human/input", "robot/intention", "robot/state", "observer/labels"};

// A stamp of `process`'s clock moved onto the recorder's process's clock; a process without a
// measured offset (or the recorder's own) keeps its stamps.
double OnRecorderClock(const std::map<std::string, int64_t>& corrections, const std::string& process, double stamp) {
  auto c = corrections.find(process);
  return c == corrections.end() ? stamp : stamp - static_cast<double>(c->second);
}

// The columns ComponentStamp reads: the writer's name only when there is a clock to correct.
std::vector<std::string> StampColumns(const std::map<std::string, int64_t>& corrections) {
  if (corrections.empty()) return {"header.stamp_ns"};
  return {"header.stamp_ns", "header.source"};
}

// A row's stamp (`column`, a stamp of its writer's clock) on the recorder's process's clock; its
// writer is the component header.source names (one the graph does not have: the stamp as it is).
StatusOr<double> ComponentStamp(const Cells& cells, size_t row, const ExperimentPlan& plan,
                                const std::map<std::string, int64_t>& corrections, const char* column = "header.stamp_ns") {
  auto stamp = cells.Number(row, column);
  if (!stamp.ok() || corrections.empty()) return stamp;
  auto p = plan.process_of.find(cells.Text(row, "header.source"));
  return p == plan.process_of.end() ? *stamp : OnRecorderClock(corrections, p->second, *stamp);
}

// The process that wrote a dyad/params answer: its source is "dyad/<process>" (runtime/exec/
// live_params.hpp); else the process of the component it names (the one that answers for it).
std::string WriterProcess(const Cells& cells, size_t row, const ExperimentPlan& plan) {
  const std::string& source = cells.Text(row, "header.source");
  if (source.rfind("dyad/", 0) == 0) return source.substr(5);
  auto p = plan.process_of.find(cells.Text(row, "component_name"));
  return p == plan.process_of.end() ? std::string() : p->second;
}

int64_t StepOf(double stamp, int64_t t0_ns, int64_t period_ns) {
  return std::llround((stamp - static_cast<double>(t0_ns)) / static_cast<double>(period_ns));
}

// t0: the first human sample, else the first sample of any topic; none when no topic has one.
StatusOr<std::optional<int64_t>> StepZero(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                          const std::map<std::string, int64_t>& corrections,
                                          const std::vector<std::string>& stamp_columns) {
  std::optional<int64_t> t0;
  for (const char* t : kTimelineTopics) {
    auto it = tables.find(t);
    if (it == tables.end() || it->second.size() == 0) continue;
    Cells cells(t, it->second);
    if (Status s = cells.Need(stamp_columns); !s.ok()) return s;
    auto stamp = ComponentStamp(cells, 0, plan, corrections);
    if (!stamp.ok()) return stamp.status();
    const auto first = static_cast<int64_t>(*stamp);
    if (std::string(t) == "human/input") return std::optional<int64_t>(first);
    t0 = t0 ? std::min(*t0, first) : first;
  }
  return t0;
}

Status FillHuman(const Cells& c, size_t r, StepSample& s) {
  auto x = c.Number(r, "x"); auto y = c.Number(r, "y"); auto e = c.Bool(r, "engaged");
  if (!x.ok()) return x.status();
  if (!y.ok()) return y.status();
  if (!e.ok()) return e.status();
  s.human_x = *x; s.human_y = *y; s.engaged = *e;
  return Status::OK();
}

Status FillIntention(const Cells& c, size_t r, StepSample& s) {
  double* dst[] = {&s.robot_x, &s.robot_y, &s.nelbo, &s.reconstruction, &s.regulation, &s.optimisation_s};
  const char* names[] = {"x", "y", "nelbo", "reconstruction", "regulation", "optimisation_s"};
  for (int i = 0; i < 6; ++i) {
    auto v = c.Number(r, names[i]);
    if (!v.ok()) return v.status();
    *dst[i] = *v;
  }
  return Status::OK();
}

Status FillState(const Cells& c, size_t r, StepSample& s) {
  auto x = c.Number(r, "x"); auto y = c.Number(r, "y");
  if (!x.ok()) return x.status();
  if (!y.ok()) return y.status();
  s.executed_x = *x; s.executed_y = *y;
  return Status::OK();
}

Status FillLabels(const Cells& c, size_t r, StepSample& s) {
  auto g = c.Number(r, "congruence");
  if (!g.ok()) return g.status();
  s.congruence = *g;
  if (Status st = c.List(r, "human", &s.p_human); !st.ok()) return st;
  return c.List(r, "robot", &s.p_robot);
}

}  // namespace

namespace {
// A person's shortest event: with a web_human, the web component's self_report_min_hold_s (its
// default 1 s when unset), what the subject's page asks about; else 0 (every engaged run counts).
int64_t MinEventNs(const YAML::Node& components) {
  bool web_human = false;
  double min_hold_s = 1.0;
  for (const auto& entry : components) {
    const YAML::Node c = entry.second;
    const std::string type = c["type"] ? c["type"].as<std::string>() : "";
    if (type == "web_human") web_human = true;
    if (type == "web" && c["params"] && c["params"]["self_report_min_hold_s"])
      min_hold_s = c["params"]["self_report_min_hold_s"].as<double>();
  }
  return web_human ? std::llround(min_hold_s * 1e9) : 0;
}
}  // namespace

StatusOr<ExperimentPlan> PlanFromGraphYaml(const std::string& yaml) {
  ExperimentPlan plan;
  if (yaml.empty()) return plan;
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("graph metadata", std::string("YAML does not parse: ") + e.what());
  }
  try {
    if (root["graph"]) plan.graph_name = root["graph"].as<std::string>();
    const YAML::Node components = root["components"];
    if (!components || !components.IsMap()) return plan;
    for (const auto& entry : components) {  // where each component runs
      const YAML::Node c = entry.second;
      const std::string process = c["process"] ? c["process"].as<std::string>() : "";
      plan.process_of[entry.first.as<std::string>()] = process;
      if (c["type"] && c["type"].as<std::string>() == "recorder") plan.recorder_process = process;
    }
    plan.min_event_ns = MinEventNs(components);
    for (const auto& entry : components) {
      const YAML::Node c = entry.second;
      const std::string type = c["type"] ? c["type"].as<std::string>() : "";
      if (type != "human_synthetic" && type != "human_replay") continue;
      if (c["rate_hz"]) plan.period_ns = std::llround(1e9 / c["rate_hz"].as<double>());
      const YAML::Node params = c["params"];
      if (!params) break;
      if (params["dataset"]) plan.dataset = params["dataset"].as<std::string>();
      if (params["events"] && params["events"].IsSequence()) {
        for (const YAML::Node& e : params["events"]) {
          PlannedEvent ev;
          ev.start_step = e["start"].as<int64_t>();
          ev.end_step = e["end"].as<int64_t>();
          ev.primitive = e["primitive"].as<int>();
          plan.events.push_back(ev);
        }
      }
      break;
    }
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("graph metadata", std::string("unexpected YAML: ") + e.what());
  }
  return plan;
}

StatusOr<std::map<std::string, int64_t>> ClockCorrections(const std::map<std::string, TopicTable>& tables,
                                                          const ExperimentPlan& plan) {
  std::map<std::string, int64_t> out;
  auto it = tables.find("dyad/clock_offsets");
  if (it == tables.end() || plan.recorder_process.empty()) return out;
  Cells cells("dyad/clock_offsets", it->second);
  if (Status s = cells.Need({"process_name", "peer_process", "offset_ns", "round_trip_ns"}); !s.ok()) return s;
  std::map<std::string, double> best_round_trip;
  for (size_t r = 0; r < it->second.size(); ++r) {
    if (cells.Text(r, "process_name") != plan.recorder_process) continue;
    const std::string peer = cells.Text(r, "peer_process");
    auto offset = cells.Number(r, "offset_ns");
    auto rtt = cells.Number(r, "round_trip_ns");
    if (!offset.ok()) return offset.status();
    if (!rtt.ok()) return rtt.status();
    auto b = best_round_trip.find(peer);
    if (b != best_round_trip.end() && b->second <= *rtt) continue;
    best_round_trip[peer] = *rtt;
    out[peer] = static_cast<int64_t>(std::llround(*offset));
  }
  return out;
}

StatusOr<Timeline> BuildTimeline(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                 const std::map<std::string, int64_t>& corrections) {
  Timeline timeline;
  timeline.clock_corrections_ns = corrections;
  const std::vector<std::string> stamp_columns = StampColumns(corrections);
  for (const char* t : kTimelineTopics) {
    auto it = tables.find(t);
    if (it == tables.end() || it->second.size() == 0) timeline.missing_topics.push_back(t);
  }
  auto t0 = StepZero(tables, plan, corrections, stamp_columns);
  if (!t0.ok()) return t0.status();
  if (!t0->has_value()) return timeline;
  timeline.t0_ns = *t0;

  auto at = [&](double stamp) -> StepSample* {
    const int64_t step = StepOf(stamp, **t0, plan.period_ns);
    if (step < 0) return nullptr;
    while (static_cast<int64_t>(timeline.steps.size()) <= step) {
      timeline.steps.push_back(EmptyStep(static_cast<int64_t>(timeline.steps.size())));
    }
    return &timeline.steps[step];
  };
  // Each topic fills its fields of the step its row's stamp falls on.
  using Fill = Status (*)(const Cells&, size_t, StepSample&);
  const std::tuple<const char*, std::vector<std::string>, Fill> topics[] = {
      {"human/input", {"x", "y", "engaged"}, FillHuman},
      {"robot/intention", {"x", "y", "nelbo", "reconstruction", "regulation", "optimisation_s"}, FillIntention},
      {"robot/state", {"x", "y"}, FillState},
      {"observer/labels", {"human", "robot", "congruence"}, FillLabels},
  };
  for (const auto& [topic, fields, fill] : topics) {
    auto it = tables.find(topic);
    if (it == tables.end()) continue;
    Cells cells(topic, it->second);
    std::vector<std::string> need = fields;
    need.insert(need.end(), stamp_columns.begin(), stamp_columns.end());
    if (Status s = cells.Need(need); !s.ok()) return s;
    for (size_t r = 0; r < it->second.size(); ++r) {
      auto stamp = ComponentStamp(cells, r, plan, corrections);
      if (!stamp.ok()) return stamp.status();
      StepSample* s = at(*stamp);
      if (s == nullptr) continue;
      if (Status st = fill(cells, r, *s); !st.ok()) return st;
    }
  }
  for (const StepSample& s : timeline.steps)
    timeline.classes = std::max<int>(timeline.classes, static_cast<int>(std::max(s.p_human.size(), s.p_robot.size())));
  return timeline;
}

StatusOr<std::vector<ParamChangeEvent>> AppliedParamChanges(const std::map<std::string, TopicTable>& tables,
                                                            const ExperimentPlan& plan, const Timeline& timeline) {
  std::vector<ParamChangeEvent> out;
  auto it = tables.find("dyad/params");
  if (it == tables.end()) return out;
  Cells cells("dyad/params", it->second);
  if (Status s = cells.Need({"header.source", "header.stamp_ns", "graph_name", "component_name", "param_name", "op",
                             "value", "old_value", "who"});
      !s.ok())
    return s;
  std::optional<int64_t> t0 = timeline.t0_ns;
  for (size_t r = 0; r < it->second.size(); ++r) {
    if (cells.Text(r, "op") != "applied") continue;  // refusals changed nothing; "value" answers a get
    const std::string& graph = cells.Text(r, "graph_name");
    if (!plan.graph_name.empty() && !graph.empty() && graph != plan.graph_name) continue;
    auto stamp = cells.Number(r, "header.stamp_ns");
    if (!stamp.ok()) return stamp.status();
    const double on_recorder = OnRecorderClock(timeline.clock_corrections_ns, WriterProcess(cells, r, plan), *stamp);
    if (!t0) t0 = static_cast<int64_t>(on_recorder);
    ParamChangeEvent e;
    e.step = StepOf(on_recorder, *t0, plan.period_ns);
    e.time_s = static_cast<double>(e.step * plan.period_ns) / 1e9;  // 1.2, not 12 * 0.1 = 1.2000000000000002 (CSV prints it exactly)
    e.component = cells.Text(r, "component_name");
    e.param = cells.Text(r, "param_name");
    e.old_value = cells.Text(r, "old_value");
    e.value = cells.Text(r, "value");
    e.who = cells.Text(r, "who");
    out.push_back(std::move(e));
  }
  return out;
}

StatusOr<std::vector<SelfReportEvent>> SelfReports(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                   const Timeline& timeline) {
  std::vector<SelfReportEvent> out;
  auto it = tables.find("human/self_report");
  if (it == tables.end()) return out;
  Cells cells("human/self_report", it->second);
  if (Status s = cells.Need({"header.source", "choice", "response_s", "segment_start_ns", "segment_end_ns"}); !s.ok()) return s;
  const auto& corrections = timeline.clock_corrections_ns;
  std::optional<int64_t> t0 = timeline.t0_ns;
  for (size_t r = 0; r < it->second.size(); ++r) {
    auto start = ComponentStamp(cells, r, plan, corrections, "segment_start_ns");
    if (!start.ok()) return start.status();
    auto end = ComponentStamp(cells, r, plan, corrections, "segment_end_ns");
    if (!end.ok()) return end.status();
    auto choice = cells.Number(r, "choice");
    if (!choice.ok()) return choice.status();
    auto response = cells.Number(r, "response_s");
    if (!response.ok()) return response.status();
    if (!(*choice >= -1 && *choice <= 1e6) || *choice != std::floor(*choice))
      return Status::DataLoss("topic human/self_report message " + std::to_string(r + 1),
                              "field \"choice\" holds " + cells.Text(r, "choice") + ": not a primitive index or -1");
    if (!t0) t0 = static_cast<int64_t>(*start);
    SelfReportEvent e;
    e.start_step = StepOf(*start, *t0, plan.period_ns);
    e.end_step = StepOf(*end, *t0, plan.period_ns);
    e.choice = static_cast<int>(*choice);
    e.response_s = *response;
    out.push_back(e);
  }
  return out;
}

void AttachSelfReports(const std::vector<SelfReportEvent>& reports, std::vector<PlannedEvent>* events) {
  for (const SelfReportEvent& r : reports) {
    PlannedEvent* best = nullptr;
    int64_t best_overlap = 0;
    for (PlannedEvent& e : *events) {
      const int64_t overlap = std::min(e.end_step, r.end_step) - std::max(e.start_step, r.start_step);
      if (overlap > best_overlap) best = &e, best_overlap = overlap;
    }
    if (best == nullptr || best->reported != kNotReported) continue;
    best->reported = r.choice;
    if (best->primitive < 0 && r.choice >= 0) best->primitive = r.choice;
  }
}

StatusOr<std::vector<PracticeSpan>> PracticeSpans(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                  const Timeline& timeline) {
  std::vector<PracticeSpan> out;
  auto it = tables.find("subject/task");
  if (it == tables.end()) return out;
  Cells cells("subject/task", it->second);
  if (Status s = cells.Need({"header.source", "header.stamp_ns", "practice"}); !s.ok()) return s;
  std::optional<int64_t> t0 = timeline.t0_ns;
  bool open = false;
  for (size_t r = 0; r < it->second.size(); ++r) {
    auto stamp = ComponentStamp(cells, r, plan, timeline.clock_corrections_ns);
    if (!stamp.ok()) return stamp.status();
    bool practice = false;
    if (!ParseBool(cells.Text(r, "practice"), &practice))
      return Status::DataLoss("topic subject/task message " + std::to_string(r + 1),
                              "field \"practice\" holds " + cells.Text(r, "practice") + ": not a bool");
    if (!t0) t0 = static_cast<int64_t>(*stamp);
    const int64_t step = StepOf(*stamp, *t0, plan.period_ns);
    if (practice && !open) out.push_back({step, std::numeric_limits<int64_t>::max()}), open = true;
    if (!practice && open) out.back().end_step = step, open = false;
  }
  return out;
}

StatusOr<std::vector<NoteEvent>> ExperimenterNotes(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                   const Timeline& timeline) {
  std::vector<NoteEvent> out;
  auto it = tables.find("experiment/notes");
  if (it == tables.end()) return out;
  Cells cells("experiment/notes", it->second);
  if (Status s = cells.Need({"header.source", "header.stamp_ns", "author", "text"}); !s.ok()) return s;
  std::optional<int64_t> t0 = timeline.t0_ns;
  for (size_t r = 0; r < it->second.size(); ++r) {
    auto stamp = ComponentStamp(cells, r, plan, timeline.clock_corrections_ns);
    if (!stamp.ok()) return stamp.status();
    if (!t0) t0 = static_cast<int64_t>(*stamp);
    NoteEvent n;
    n.step = StepOf(*stamp, *t0, plan.period_ns);
    n.time_s = static_cast<double>(n.step * plan.period_ns) / 1e9;
    n.author = cells.Text(r, "author");
    n.text = cells.Text(r, "text");
    out.push_back(std::move(n));
  }
  return out;
}

int DropPracticeEvents(const std::vector<PracticeSpan>& spans, std::vector<PlannedEvent>* events) {
  const auto in_practice = [&spans](const PlannedEvent& e) {
    return std::any_of(spans.begin(), spans.end(), [&e](const PracticeSpan& s) { return e.start_step >= s.start_step && e.start_step < s.end_step; });
  };
  const size_t before = events->size();
  events->erase(std::remove_if(events->begin(), events->end(), in_practice), events->end());
  return static_cast<int>(before - events->size());
}

int MostLikelyClass(const std::vector<double>& p) {
  if (p.empty()) return -1;
  return static_cast<int>(std::max_element(p.begin(), p.end()) - p.begin());
}

std::vector<PlannedEvent> Events(const Timeline& timeline, const ExperimentPlan& plan) {
  std::vector<PlannedEvent> events;
  const auto recorded = static_cast<int64_t>(timeline.steps.size());
  if (!plan.events.empty()) {
    // A run shorter than the plan (--steps): later events never happened, the last may be cut.
    for (PlannedEvent e : plan.events) {
      if (e.start_step >= recorded) continue;
      e.end_step = std::min(e.end_step, recorded);
      events.push_back(e);
    }
    return events;
  }
  for (size_t i = 0; i < timeline.steps.size(); ++i) {
    if (!timeline.steps[i].engaged) continue;
    if (events.empty() || events.back().end_step != static_cast<int64_t>(i)) {
      events.push_back(PlannedEvent{static_cast<int64_t>(i), static_cast<int64_t>(i), -1});
    }
    events.back().end_step = static_cast<int64_t>(i) + 1;
  }
  // Taps: the page asked nothing about them (a hold shorter than its self_report_min_hold_s).
  std::erase_if(events, [&](const PlannedEvent& e) { return (e.end_step - e.start_step) * plan.period_ns < plan.min_event_ns; });
  return events;
}

std::vector<EventSummary> SummariseEvents(const Timeline& timeline, const std::vector<PlannedEvent>& events) {
  std::vector<EventSummary> out;
  for (size_t e = 0; e < events.size(); ++e) {
    EventSummary sum;
    sum.index = static_cast<int>(e);
    sum.event = events[e];
    sum.mean_congruence = sum.final_congruence = sum.human_accuracy = sum.robot_follows = kNaN;
    double congruence_total = 0, human_hits = 0, robot_hits = 0;
    int labelled = 0;
    const int64_t end = std::min<int64_t>(events[e].end_step, static_cast<int64_t>(timeline.steps.size()));
    for (int64_t t = std::max<int64_t>(events[e].start_step, 0); t < end; ++t) {
      const StepSample& s = timeline.steps[t];
      if (std::isnan(s.congruence)) continue;
      ++labelled;
      congruence_total += s.congruence;
      sum.final_congruence = s.congruence;
      if (events[e].primitive >= 0) {
        human_hits += MostLikelyClass(s.p_human) == events[e].primitive;
        if (MostLikelyClass(s.p_robot) == events[e].primitive) {
          robot_hits += 1;
          if (sum.robot_switch_after < 0) sum.robot_switch_after = t - events[e].start_step;
        }
      }
    }
    if (labelled > 0) {
      sum.mean_congruence = congruence_total / labelled;
      if (events[e].primitive >= 0) {
        sum.human_accuracy = human_hits / labelled;
        sum.robot_follows = robot_hits / labelled;
      }
    }
    out.push_back(sum);
  }
  return out;
}

namespace {
// counts[truth(e)][argmax p_human] over the labelled steps of events whose truth is a class.
template <class Truth>
std::vector<std::vector<int64_t>> Confusion(const Timeline& timeline, const std::vector<PlannedEvent>& events, Truth truth) {
  std::vector<std::vector<int64_t>> counts;
  if (timeline.classes == 0) return counts;
  counts.assign(timeline.classes, std::vector<int64_t>(timeline.classes, 0));
  bool any = false;
  for (const PlannedEvent& e : events) {
    const int row = truth(e);
    if (row < 0 || row >= timeline.classes) continue;
    const int64_t end = std::min<int64_t>(e.end_step, static_cast<int64_t>(timeline.steps.size()));
    for (int64_t t = std::max<int64_t>(e.start_step, 0); t < end; ++t) {
      const int predicted = MostLikelyClass(timeline.steps[t].p_human);
      if (predicted < 0 || predicted >= timeline.classes) continue;
      ++counts[row][predicted];
      any = true;
    }
  }
  if (!any) counts.clear();
  return counts;
}
}  // namespace

std::vector<std::vector<int64_t>> HumanConfusion(const Timeline& timeline, const std::vector<PlannedEvent>& events) {
  return Confusion(timeline, events, [](const PlannedEvent& e) { return e.primitive; });
}

std::vector<std::vector<int64_t>> ReportedConfusion(const Timeline& timeline, const std::vector<PlannedEvent>& events) {
  return Confusion(timeline, events, [](const PlannedEvent& e) { return e.reported; });
}

}  // namespace dyad::analyze
