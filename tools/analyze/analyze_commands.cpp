#include "analyze_commands.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <sstream>
#include <memory>
#include <string>
#include <vector>

#include "build_report.hpp"
#include "demonstrations.hpp"
#include "dyad/mcap/reader.hpp"
#include "exit_code.hpp"
#include "experiment_analysis.hpp"
#include "losses.hpp"
#include "recording_tables.hpp"
#include "report_writer.hpp"
#include "run_process.hpp"

namespace dyad::cli {
namespace {

using tools::ExitCode;
using enum tools::ExitCode;

struct Options {
  std::string recording, out, dataset;
  double duration_s = 0;  // the run's planned length: a shorter recording is incomplete
  bool plots = true;
};

ExitCode RunAnalyze(const Options& o) {
  if (!o.dataset.empty() && !std::filesystem::is_directory(o.dataset)) {
    std::cerr << "dyad analyze: --dataset " << o.dataset << ": not a folder\n";
    return kBadInput;
  }
  std::ostringstream warnings;
  auto built = analyze::BuildReport(o.recording, warnings);
  std::cerr << warnings.str();
  if (!built.ok()) {
    std::cerr << "dyad analyze: " << built.status().message() << "\n";
    return kBadInput;
  }
  analyze::Report& report = *built;
  report.planned_s = o.duration_s;
  const std::string incomplete = analyze::IncompleteReason(report);
  if (!incomplete.empty()) std::cerr << "dyad analyze: " << o.recording << ": incomplete recording: " << incomplete << "\n";

  std::string out = o.out;
  if (out.empty()) {
    std::filesystem::path p(o.recording);
    out = (p.parent_path() / (p.stem().string() + "_report")).string();
  }
  if (Status s = analyze::WriteReport(report, out); !s.ok()) {
    std::cerr << "dyad analyze: " << s.message() << "\n";
    return kFailure;
  }
  std::cout << "report: " << out << "/report.md (" << report.timeline.steps.size() << " steps, "
            << report.events.size() << " events" << (incomplete.empty() ? "" : "; incomplete, its first lines say why") << ")\n";
  if (!o.plots) return kOk;
  const std::string script = tools::DyadScriptPath("plot_report.py");
  if (!std::filesystem::exists(script)) {
    std::cerr << "dyad analyze: plot script not found at " << script << "\n";
    return kFailure;
  }
  std::vector<std::string> args = {out};
  std::string dataset = o.dataset.empty() ? report.plan.dataset : o.dataset;
  if (!dataset.empty()) {
    if (std::filesystem::is_directory(dataset)) {
      args.push_back("--dataset");
      args.push_back(dataset);
    } else {
      std::cerr << "dyad analyze: the graph's dataset " << dataset
                << " is not a folder from here; plots drawn without the watermark (pass --dataset)\n";
    }
  }
  const tools::ExitStatus code = tools::RunDyadScript("plot_report.py", args);
  if (!code.ok()) {
    std::cerr << "dyad analyze: " << script << " failed (" << code.ToString()
              << "); is python3-matplotlib installed (tools/setup.sh)?\n";
    return kFailure;
  }
  std::cout << "plots: " << out << "/workspace.png, nelbo.png, congruence.png\n";
  return kOk;
}

struct FromRecordingOptions {
  std::string recording, out, preview;
  std::vector<std::string> names;  // --names: one per primitive, in order (names.txt)
  analyze::DemonstrationOptions demo;
};

// The segments found and which became which primitive; the warnings (see demonstrations.hpp).
void SayWhatWasCut(const analyze::Demonstrations& d, std::ostream& out, std::ostream& err) {
  out << "segments (engaged, in recording order):\n";
  char line[160];
  for (size_t i = 0; i < d.segments.size(); ++i) {
    const auto& s = d.segments[i];
    std::string used;
    for (size_t k = 0; k < d.chosen.size(); ++k)
      if (d.chosen[k] == static_cast<int>(i)) used += (used.empty() ? " -> primitive " : ", ") + std::to_string(k);
    std::snprintf(line, sizeof line, "  %2zu  at %7.1f s  %5.1f s  %4d samples  %d lap%s", i, s.start_s, s.duration_s, s.samples,
                  s.laps, s.laps == 1 ? "" : "s");
    out << line << (used.empty() ? "  (not used)" : used) << "\n";
  }
  for (const auto& w : d.warnings) err << "warning: " << w << "\n";
}

// --preview: the primitives drawn, each titled with its segment (and its first warning).
ExitCode DrawPreview(const FromRecordingOptions& o, const analyze::Demonstrations& d) {
  std::vector<std::string> args = {o.out, o.preview};
  for (size_t k = 0; k < d.chosen.size(); ++k) {
    std::string label = "primitive " + std::to_string(k) + " <- segment " + std::to_string(d.chosen[k]);
    const auto& s = d.segments[static_cast<size_t>(d.chosen[k])];
    if (s.laps > 1) label += "\n(" + std::to_string(s.laps) + " laps!)";
    args.insert(args.end(), {"--label", std::to_string(k) + "=" + label});
  }
  if (tools::ExitStatus code = tools::RunDyadScript("plot_dataset.py", args); !code.ok()) {
    std::cerr << "dyad dataset from-recording: the preview was not drawn (" << code.ToString()
              << "; python3-matplotlib: tools/setup.sh)\n";
    return kFailure;
  }
  std::cout << "preview: " << o.preview << "\n";
  return kOk;
}

ExitCode RunFromRecording(const FromRecordingOptions& o) {
  auto reader = mcap::Reader::Open(o.recording);
  if (!reader.ok()) {
    std::cerr << "dyad dataset from-recording: " << reader.status().message() << "\n";
    return kBadInput;
  }
  auto tables = analyze::ReadTables(*reader, {o.demo.topic});
  if (!tables.ok()) {
    std::cerr << "dyad dataset from-recording: " << o.recording << ": " << tables.status().message() << "\n";
    return kBadInput;
  }
  auto it = tables->find(o.demo.topic);
  if (it == tables->end()) {
    std::cerr << "dyad dataset from-recording: " << o.recording << ": no topic '" << o.demo.topic << "' (--topic)\n";
    return kBadInput;
  }
  auto demos = analyze::DemonstrationsFromTable(it->second, o.demo);
  if (!demos.ok()) {
    std::cerr << "dyad dataset from-recording: " << o.recording << ": " << demos.status().message() << "\n";
    return kBadInput;
  }
  if (!o.names.empty() && static_cast<int>(o.names.size()) != demos->dataset.size()) {
    std::cerr << "dyad dataset from-recording: --names gives " << o.names.size() << " names for " << demos->dataset.size()
              << " primitive(s)\n";
    return kBadInput;
  }
  demos->dataset.names = o.names;
  if (Status s = pvrnn::WriteNrlDataset(demos->dataset, o.out); !s.ok()) {
    std::cerr << "dyad dataset from-recording: " << s.message() << "\n";
    return kFailure;
  }
  SayWhatWasCut(*demos, std::cout, std::cerr);
  std::cout << o.out << ": " << demos->dataset.size() << " primitive(s) of " << o.demo.steps << " steps from the engaged segments of '"
            << o.demo.topic << "'";
  if (demos->skipped > 0) std::cout << " (" << demos->skipped << " shorter than " << o.demo.min_samples << " samples skipped)";
  std::cout << "\n" << std::flush;
  return o.preview.empty() ? kOk : DrawPreview(o, *demos);
}

}  // namespace

void AddAnalyzeCommands(CLI::App& app, int& exit_code) {
  {
    auto o = std::make_shared<FromRecordingOptions>();
    CLI::App* ds = app.add_subcommand("dataset", "Make data sets");
    ds->require_subcommand(1);
    CLI::App* fr = ds->add_subcommand("from-recording",
                                      "Cut a recording's engaged segments (a person's demonstrations) into an NRL data set");
    fr->add_option("recording", o->recording, "MCAP file with the human's topic")->required();
    fr->add_option("--out", o->out, "data set folder (NRL layout: dataset.d, primitive_<id>_0.csv)")->required();
    fr->add_option("--topic", o->demo.topic, "HumanInput topic (default human/input)");
    fr->add_option("--steps", o->demo.steps, "steps T of every primitive (default 72)");
    fr->add_option("--min-samples", o->demo.min_samples, "shorter engaged segments are skipped (default 10)");
    fr->add_option("--segments", o->demo.choose, "which segments become the primitives, in order, e.g. 2,0,1 (default: all)")
        ->delimiter(',');
    fr->add_option("--names", o->names, "the primitives' names, in order, e.g. circle,star (names.txt: pages and reports use them)")
        ->delimiter(',');
    fr->add_option("--preview", o->preview, "PNG file: the primitives drawn, each with its segment");
    fr->callback([o, &exit_code] { exit_code = tools::Code(RunFromRecording(*o)); });
  }
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("analyze", "Write a report folder (tables, PNG plots) for an experiment recording");
  cmd->add_option("recording", options->recording, "MCAP file written by the recorder")->required();
  cmd->add_option("-o,--out", options->out, "report folder (default: RECORDING without .mcap + _report)");
  cmd->add_option("--dataset", options->dataset, "data set folder drawn as watermark (default: the graph's human dataset)");
  cmd->add_option("--duration", options->duration_s,
                  "the run's planned seconds: a recording under 95% of them is reported incomplete (as a cut-short file is)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("!--no-plots", options->plots, "write tables only");
  cmd->callback([options, &exit_code] { exit_code = tools::Code(RunAnalyze(*options)); });
}

}  // namespace dyad::cli
