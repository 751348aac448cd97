#include "build_report.hpp"

#include <filesystem>

#include "dyad/mcap/reader.hpp"
#include "dyad/pvrnn/dataset.hpp"
#include "experiment_analysis.hpp"
#include "losses.hpp"
#include "recording_tables.hpp"

namespace dyad::analyze {

StatusOr<Report> BuildReport(const std::string& recording, std::ostream& warnings) {
  auto reader = mcap::Reader::Open(recording);
  if (!reader.ok()) return reader.status();
  const mcap::Recovery& recovery = reader->recovery();
  if (recovery.truncated) warnings << "dyad analyze: " << recording << ": " << recovery.Describe() << "\n";
  Report report;
  report.recording = recording;
  // Without its footer the file is not what the recorder closed, even when no message was lost.
  if (recovery.truncated || !recovery.damaged_chunks.empty()) report.incomplete = recovery.Describe();
  if (const mcap::Statistics& stats = reader->statistics(); stats.message_count > 0)
    report.message_span_s = static_cast<double>(stats.message_end_time - stats.message_start_time) / 1e9;
  report.graph_yaml = GraphMetadata(*reader, "yaml");
  auto plan = PlanFromGraphYaml(report.graph_yaml);
  if (!plan.ok()) return plan.status().WithContext(recording);
  report.plan = *plan;
  // The graph's data set path is relative to the graph file's folder (recorded with it).
  if (const std::string folder = GraphMetadata(*reader, "folder");
      !folder.empty() && !report.plan.dataset.empty() && std::filesystem::path(report.plan.dataset).is_relative())
    report.plan.dataset = (std::filesystem::path(folder) / report.plan.dataset).lexically_normal().string();
  // The primitives' names, when the graph's data set is here and names them ("heart (5)").
  if (std::error_code ec; !report.plan.dataset.empty() && std::filesystem::is_directory(report.plan.dataset, ec)) {
    auto data = pvrnn::LoadNrlDataset(report.plan.dataset);
    if (data.ok()) report.primitive_names = data->names;
    else warnings << "dyad analyze: " << recording << ": the primitives' names not read: " << data.status().message() << "\n";
  }
  auto tables = ReadTables(*reader, {"human/input", "robot/intention", "robot/state", "observer/labels",
                                     "dyad/clock_offsets", "dyad/params", "human/self_report", "subject/task",
                                     "experiment/notes"});
  if (!tables.ok()) return tables.status();
  auto corrections = ClockCorrections(*tables, report.plan);
  if (!corrections.ok()) return corrections.status().WithContext(recording);
  auto timeline = BuildTimeline(*tables, report.plan, *corrections);
  if (!timeline.ok()) return timeline.status().WithContext(recording);
  report.timeline = std::move(*timeline);
  auto changes = AppliedParamChanges(*tables, report.plan, report.timeline);
  if (!changes.ok()) return changes.status().WithContext(recording);
  report.param_changes = std::move(*changes);
  auto notes = ExperimenterNotes(*tables, report.plan, report.timeline);
  if (!notes.ok()) return notes.status().WithContext(recording);
  report.notes = std::move(*notes);
  if (auto losses = bag::FindLosses(*reader); losses.ok()) report.transport = bag::FormatLosses(*losses);
  else warnings << "dyad analyze: " << recording << ": losses not read: " << losses.status().message() << "\n";
  auto events = Events(report.timeline, report.plan);
  auto reports = SelfReports(*tables, report.plan, report.timeline);
  if (!reports.ok()) return reports.status().WithContext(recording);
  AttachSelfReports(*reports, &events);
  auto practice = PracticeSpans(*tables, report.plan, report.timeline);
  if (!practice.ok()) return practice.status().WithContext(recording);
  report.practice_events = DropPracticeEvents(*practice, &events);
  report.events = SummariseEvents(report.timeline, events);
  report.confusion = HumanConfusion(report.timeline, events);
  report.reported_confusion = ReportedConfusion(report.timeline, events);
  return report;
}

}  // namespace dyad::analyze
