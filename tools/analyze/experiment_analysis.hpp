// tools/analyze/experiment_analysis.hpp: what `dyad analyze` computes from a recording of the
// study's experiment graph (topics as in configs/demo.yaml, see docs/components.md).
//
//   human/input      HumanInput      -> human position, engagement
//   robot/intention  Intention       -> robot intention, N-ELBO and its terms
//   robot/state      CartesianState  -> executed position
//   observer/labels  IntentionLabel  -> class probabilities of human and robot, congruence P(C_t)
//   dyad/params      ParamChange     -> live parameter changes applied during the run
//   human/self_report SelfReport     -> what the person said they drew
//   subject/task     SubjectTask     -> practice: events that start meanwhile are left out
//
// Samples are put on one step grid: step = round((stamp - t0) / period), t0 the first human
// sample's stamp, period from the graph (the human source's rate_hz; 100 ms if unknown). A topic
// missing from the recording leaves its fields NaN; the report says which topics were missing.
//
// Clocks: in a graph split over processes (hosts), each sample is stamped by its writer's clock.
// When the recording holds dyad/clock_offsets (docs/distributed.md), each stamp is first moved
// onto the recorder's process's clock: stamp - offset(writer's process), the offset being the
// one the recorder's process measured of that process with the least round trip.
//
// Events are the human's interventions: taken from the graph's human_synthetic `events` (with the
// primitive the human traced, so confusion and "robot follows" can be scored), else from runs of
// engaged steps (primitive unknown: -1). A person's run shorter than the subject's page's
// `self_report_min_hold_s` (a graph with a `web_human`: the `web` component's, 1 s when unset) is
// a tap, not an event: the page never asks about it, and the analysis does not count it.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "recording_tables.hpp"

namespace dyad::analyze {

// An event's self-report when it has none (a SelfReport's choice -1 is "something else").
constexpr int kNotReported = -2;

struct PlannedEvent {
  int64_t start_step = 0;  // first engaged step
  int64_t end_step = 0;    // one past the last
  int primitive = -1;      // traced primitive; -1 unknown
  int reported = kNotReported;  // what the person said they drew (AttachSelfReports)
};

// What the graph YAML says about the experiment; every field has a usable default.
struct ExperimentPlan {
  std::string graph_name;
  int64_t period_ns = 100'000'000;
  std::vector<PlannedEvent> events;  // empty when the human is not human_synthetic
  std::string dataset;               // the human's dataset param, "" if none
  std::map<std::string, std::string> process_of;  // component -> its process ("" when one process)
  std::string recorder_process;                   // the process of the recorder, "" if none
  // An engaged run shorter than this is no event (a tap); 0: every run is one. A graph with a
  // web_human: its web component's self_report_min_hold_s (1 s when unset).
  int64_t min_event_ns = 0;
};

// Per process, what to subtract from its stamps to put them on the recorder's process's clock
// (ns), from the dyad/clock_offsets table; empty when the recording has none (one process).
StatusOr<std::map<std::string, int64_t>> ClockCorrections(const std::map<std::string, TopicTable>& tables,
                                                          const ExperimentPlan& plan);

// Tolerant: a recording without graph metadata, or a graph without a synthetic human, gives the
// defaults. Fails (InvalidArgument) only on YAML that does not parse.
StatusOr<ExperimentPlan> PlanFromGraphYaml(const std::string& yaml);

struct StepSample {
  int64_t step = 0;
  double human_x, human_y;  // NaN when no sample this step
  bool engaged = false;
  double robot_x, robot_y, nelbo, reconstruction, regulation, optimisation_s;
  double executed_x, executed_y;
  double congruence;
  std::vector<double> p_human, p_robot;  // empty when no label this step
};

struct Timeline {
  std::vector<StepSample> steps;  // steps[i].step == i
  std::vector<std::string> missing_topics;
  int classes = 0;  // length of the observer's probability vectors (0: no observer)
  std::map<std::string, int64_t> clock_corrections_ns;  // applied, per process (see above)
  // The stamp of step 0 (recorder's process's clock): what other samples are placed against
  // (AppliedParamChanges). Empty when no topic of the timeline has a sample.
  std::optional<int64_t> t0_ns;
};

// `corrections`: ClockCorrections(); stamps of components of other processes are used as they are.
StatusOr<Timeline> BuildTimeline(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                 const std::map<std::string, int64_t>& corrections = {});

// A live parameter change the component's process applied (idl/param.idl, op "applied"). It
// took effect at the component's step boundary: its Step() used `value` from then on.
struct ParamChangeEvent {
  int64_t step = 0;     // on the timeline's grid (see below); negative: before step 0
  double time_s = 0;    // step * period, as timeline.csv's time_s
  std::string component, param;
  std::string old_value, value;  // YAML flow text, before and after
  std::string who;               // who asked, e.g. "dyad param set (ana@lab-pc)"
};

// The applied changes of dyad/params, in recording order, on `timeline`'s step grid the way
// BuildTimeline places samples: the answer's stamp moved onto the recorder's process's clock by
// timeline.clock_corrections_ns (the writer's process: header.source "dyad/<process>", else the
// component's), then step = round((stamp - t0_ns) / period). Answers naming another graph than
// the plan's (a recorder on a shared domain) are left out. Without t0_ns (no experiment topic
// recorded) the first change's stamp is step 0. No dyad/params: empty. Fails (DataLoss) on a
// table without ParamChange's fields or with a stamp that is not a number.
StatusOr<std::vector<ParamChangeEvent>> AppliedParamChanges(const std::map<std::string, TopicTable>& tables,
                                                            const ExperimentPlan& plan, const Timeline& timeline);

// A note the experimenter wrote during the run (idl/annotation.idl Annotation, topic
// experiment/notes: the web component's `notes` output), placed on the step grid as
// AppliedParamChanges places stamps (the writer's process is that of header.source's component).
struct NoteEvent {
  int64_t step = 0;
  double time_s = 0;  // step * period, as timeline.csv's time_s
  std::string author, text;
};
// No experiment/notes: empty. Fails (DataLoss) on a table without Annotation's fields or with a
// stamp that is not a number.
StatusOr<std::vector<NoteEvent>> ExperimenterNotes(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                   const Timeline& timeline);

// Events of the plan, or engaged runs of the timeline when the plan has none (those shorter than
// plan.min_event_ns left out: taps). Planned events are
// limited to the recorded steps: one starting after the last recorded step is left out (the run
// ended before it), one running past it ends there.
std::vector<PlannedEvent> Events(const Timeline& timeline, const ExperimentPlan& plan);

// A person's answer after a release (idl/human.idl SelfReport, topic human/self_report), its
// segment on the timeline's grid as AppliedParamChanges places stamps (the writer's process is
// that of the component header.source names).
struct SelfReportEvent {
  int64_t start_step = 0;  // the segment's first engaged step
  int64_t end_step = 0;    // its release
  int choice = -1;         // a primitive; -1: "something else"
  double response_s = 0;
};
// No human/self_report: empty. Fails (DataLoss) on a table without SelfReport's fields or with a
// cell that is not a number.
StatusOr<std::vector<SelfReportEvent>> SelfReports(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                   const Timeline& timeline);

// Gives each report to the event its segment overlaps most (the earlier on ties; a report that
// overlaps none is left out, and an event keeps its first report). An event of unknown primitive
// (a person's) takes a reported primitive as its primitive: what the observer is judged against.
void AttachSelfReports(const std::vector<SelfReportEvent>& reports, std::vector<PlannedEvent>* events);

// Steps [start_step, end_step) the subject's page said "practice" (subject/task, the web
// component's `task` output: each sample holds from its stamp until the next; the last until the
// end). Stamps placed as SelfReports places them. No subject/task: empty. Fails (DataLoss) on a
// table without SubjectTask's fields.
struct PracticeSpan {
  int64_t start_step = 0, end_step = 0;
};
StatusOr<std::vector<PracticeSpan>> PracticeSpans(const std::map<std::string, TopicTable>& tables, const ExperimentPlan& plan,
                                                  const Timeline& timeline);
// Leaves out the events that start inside a span; returns how many.
int DropPracticeEvents(const std::vector<PracticeSpan>& spans, std::vector<PlannedEvent>* events);

// Index of the largest probability (the first on ties); -1 for an empty vector (no label).
int MostLikelyClass(const std::vector<double>& p);

struct EventSummary {
  int index = 0;
  PlannedEvent event;
  double mean_congruence = 0;   // over the event's steps that carry a label (NaN: none)
  double final_congruence = 0;  // at its last labelled step
  double human_accuracy = 0;    // fraction of labelled steps where argmax(p_human) == primitive
  double robot_follows = 0;     // fraction where argmax(p_robot) == primitive
  int64_t robot_switch_after = -1;  // steps from start to the first such step; -1 never
};

std::vector<EventSummary> SummariseEvents(const Timeline& timeline, const std::vector<PlannedEvent>& events);

// Confusion of the observer on the human's traces: counts[true primitive][argmax p_human] over
// the labelled steps of events with a known primitive. Empty when there are none.
std::vector<std::vector<int64_t>> HumanConfusion(const Timeline& timeline, const std::vector<PlannedEvent>& events);
// The same against what the person said: counts[reported primitive][argmax p_human] over the
// labelled steps of events with a reported primitive ("something else" is left out).
std::vector<std::vector<int64_t>> ReportedConfusion(const Timeline& timeline, const std::vector<PlannedEvent>& events);

}  // namespace dyad::analyze
