// tools/analyze/report_writer.hpp: writes the report folder of `dyad analyze`.
//
//   report.md      the tables below, for people
//   events.csv     one row per event (EventSummary)
//   confusion.csv  observer confusion on the human's traces: true,predicted,count
//   timeline.csv   one row per step: positions, engagement, N-ELBO terms, congruence, argmaxes
//   params.csv     the live parameter changes applied (only when there were some; an old one goes):
//                  step,time_s,component,param,old_value,value,who (cells quoted as RFC 4180 says)
//   graph.yaml     the recorded graph (when the recording has it)
//   metrics.json   the run in numbers (RunMetrics): what `dyad sweep` tabulates
//   incomplete.txt why the recording is incomplete (IncompleteReason), one line; only when it is
//                  (an old one goes): what a table of many runs (`dyad sweep`) reads from the folder
// Numbers in the CSV files and metrics.json are the shortest text that reads back to the same
// double (tools::CsvNumber); report.md rounds them for people. An incomplete recording
// (IncompleteReason) is said in report.md's first lines, before any number.
// The PNG plots are drawn from timeline.csv, events.csv and params.csv by
// tools/analyze/plot_report.py.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "dyad/status.hpp"
#include "experiment_analysis.hpp"

namespace dyad::analyze {

struct Report {
  std::string recording;
  std::string graph_yaml;
  ExperimentPlan plan;
  Timeline timeline;
  std::vector<EventSummary> events;
  std::vector<std::vector<int64_t>> confusion;
  std::vector<std::vector<int64_t>> reported_confusion;  // against the self-reports; empty: none
  std::vector<ParamChangeEvent> param_changes;  // applied during the run, in recording order
  std::vector<NoteEvent> notes;  // the experimenter's, in recording order
  std::vector<std::string> primitive_names;  // the plan's data set's (names.txt); empty: numbers only
  int practice_events = 0;  // events left out: they started while the subject's page said "practice"
  // What the recording lost in transport and what the runtime healed: `dyad bag info`'s losses:
  // and health: sections (tools/bag/losses.hpp); empty: not read.
  std::string transport;
  // Why the recording is not the whole run, "" when it is: the file is cut short (no footer: a
  // crash, a full disk, a cut copy; what the reader recovered) or has damaged chunks. BuildReport.
  std::string incomplete;
  // The run's planned length in seconds (0: unknown): a recording shorter than it is incomplete.
  double planned_s = 0;
  // From the first to the last message of any topic (log times), seconds; -1: no message. What
  // the length rule measures when the recording has no experiment steps (a graph of other topics).
  double message_span_s = -1;
};

// Why `report`'s recording is incomplete, "" when it is whole: Report::incomplete, else, when
// planned_s > 0, its steps span less than 95% of it ("903 steps of 100 ms (90.3 s) of the 170 s
// planned"; the slack is a wall-clock run's start-up); without experiment steps, its messages'
// span plus one period does (the same measure: n steps span n - 1 periods). `dyad analyze`, `dyad study analyze` and
// `dyad sweep` leave such a run out of their summaries by this rule.
std::string IncompleteReason(const Report& report);

// Creates `dir` if needed. Fails with IOError naming the file that cannot be written.
Status WriteReport(const Report& report, const std::string& dir);

// The report.md text (also used by tests).
std::string FormatMarkdown(const Report& report);

// The run in numbers, in a fixed order (NaN: not defined for this run, e.g. no event scored):
//   steps, engaged_fraction (of the steps), events (scored), mean_congruence and
//   final_congruence (mean over events), observer_accuracy (the observer on the human's traces),
//   robot_follows (fraction of an event's labelled steps the robot's intention matched the
//   human's primitive), switched_fraction (events where it ever did), switch_latency_s (mean
//   delay to that first step, over events that switched), nelbo_mean (over steps). Only what a
//   stepped run determines: no wall-clock timing (a sweep's table is the same on any machine).
std::vector<std::pair<std::string, double>> RunMetrics(const Report& report);

}  // namespace dyad::analyze
