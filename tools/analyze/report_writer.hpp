// tools/analyze/report_writer.hpp: writes the report folder of `dyad analyze`.
//
//   report.md      the tables below, for people
//   events.csv     one row per event (EventSummary)
//   confusion.csv  observer confusion on the human's traces: true,predicted,count
//   timeline.csv   one row per step: positions, engagement, N-ELBO terms, congruence, argmaxes
//   graph.yaml     the recorded graph (when the recording has it)
// The PNG plots are drawn from timeline.csv and events.csv by tools/analyze/plot_report.py.
#pragma once

#include <string>
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
  // What the recording lost in transport and what the runtime healed: `dyad bag info`'s losses:
  // and health: sections (tools/bag/losses.hpp); empty: not read.
  std::string transport;
};

// Creates `dir` if needed. Fails with IOError naming the file that cannot be written.
Status WriteReport(const Report& report, const std::string& dir);

// The report.md text (also used by tests).
std::string FormatMarkdown(const Report& report);

}  // namespace dyad::analyze
