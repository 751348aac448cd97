#include "bag_commands.hpp"

#include <CLI/CLI.hpp>

#include <dyad/cdr_decoder.hpp>

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bag_filter.hpp"
#include "bag_info.hpp"
#include "csv_export.hpp"
#include "dyad/mcap/reader.hpp"
#include "exit_code.hpp"
#include "losses.hpp"

namespace dyad::cli {
namespace {

using tools::ExitCode;
using enum tools::ExitCode;

// Opens a recording; prints why not and returns null when it cannot be read at all.
std::unique_ptr<mcap::Reader> OpenRecording(const std::string& path, bool scan) {
  mcap::ReaderOptions options;
  options.use_summary = !scan;
  StatusOr<mcap::Reader> reader = mcap::Reader::Open(path, options);
  if (!reader.ok()) {
    std::cerr << "dyad bag: " << reader.status().message() << "\n";
    return nullptr;
  }
  return std::make_unique<mcap::Reader>(std::move(reader).value());
}

ExitCode RunInfo(const std::string& path, bool scan) {
  auto reader = OpenRecording(path, scan);
  if (!reader) return kBadInput;
  std::cout << bag::FormatInfo(*reader);
  auto losses = bag::FindLosses(*reader);
  if (!losses.ok()) {
    std::cerr << "dyad bag: " << path << ": " << losses.status().message() << "\n";
    return kFailure;
  }
  std::cout << bag::FormatLosses(*losses);
  return reader->recovery().damaged_chunks.empty() ? kOk : kFailure;
}

// The decoder of a channel whose schema is omgidl text (what dyad records): one column per field
// (cdr::Columns). nullopt, for data_hex, when the schema is not omgidl; also when its text does not
// parse or does not define the schema's type, and then *problem says why.
std::optional<bag::PayloadDecoder> CdrDecoder(const mcap::Schema* schema, std::string* problem) {
  if (schema == nullptr || schema->encoding != "omgidl") return std::nullopt;
  const std::string what = "schema " + std::to_string(schema->id) + " \"" + schema->name + "\" (omgidl)";
  StatusOr<cdr::Schema> schema_or = cdr::Schema::Parse(schema->data);
  if (!schema_or.ok()) {
    *problem = what + ": " + schema_or.status().message();
    return std::nullopt;
  }
  const cdr::Schema& parsed = *schema_or;
  if (!parsed.HasType(schema->name)) {
    *problem = what + ": its IDL defines no struct \"" + schema->name + "\"";
    return std::nullopt;
  }
  bag::PayloadDecoder decoder;
  decoder.columns = cdr::Columns(parsed, schema->name);
  decoder.decode = [parsed, type = schema->name](std::span<const std::uint8_t> data,
                                                 std::vector<std::string>* cells) {
    return cdr::DecodeRow(parsed, type, data.data(), data.size(), cells);
  };
  return decoder;
}

ExitCode RunExport(const std::string& path, const std::string& dir, const std::vector<std::string>& topics) {
  auto reader = OpenRecording(path, false);
  if (!reader) return kBadInput;
  if (reader->recovery().truncated) std::cerr << "dyad bag: " << path << ": " << reader->recovery().Describe() << "\n";
  bag::CsvExportOptions options;
  options.topics.insert(topics.begin(), topics.end());
  std::vector<std::string> schema_problems;  // One per channel exported as hex against its schema.
  options.decoder_factory = [&](const mcap::Schema* schema, const mcap::Channel& channel) {
    std::string problem;
    std::optional<bag::PayloadDecoder> decoder = CdrDecoder(schema, &problem);
    if (!problem.empty()) schema_problems.push_back(channel.topic + ": " + problem + "; exported as data_hex");
    return decoder;
  };
  for (const std::string& topic : topics) {
    bool known = false;
    for (const auto& [id, channel] : reader->channels()) known = known || channel.topic == topic;
    if (!known) {
      std::cerr << "dyad bag: " << path << ": no channel with topic \"" << topic << "\"\n";
      return kBadInput;
    }
  }
  bag::CsvExportSummary summary;
  Status status = bag::ExportCsv(*reader, dir, options, &summary);
  for (const auto& [topic, file] : summary.files) {
    std::cout << file << ": " << summary.rows[topic] << " rows (" << topic << ")\n";
  }
  if (!status.ok()) {
    std::cerr << "dyad bag: " << status.message() << "\n";
    return kFailure;
  }
  ExitCode code = kOk;
  for (const std::string& problem : schema_problems) {
    std::cerr << "dyad bag: " << path << ": " << problem << "\n";
    code = kFailure;
  }
  if (summary.skipped_chunks > 0) {
    std::cerr << "dyad bag: " << path << ": skipped " << summary.skipped_chunks
              << " damaged chunk(s); `dyad bag info --scan " << path << "` lists them\n";
    code = kFailure;
  }
  if (summary.undecodable > 0) {
    std::cerr << "dyad bag: " << path << ": " << summary.undecodable
              << " payload(s) could not be decoded (their cells are left empty); first: "
              << summary.first_decode_error << "\n";
    code = kFailure;
  }
  return code;
}

ExitCode RunFilter(const std::string& in, const std::string& out, const bag::FilterOptions& options) {
  if (options.end_s >= 0 && options.end_s < options.start_s) {
    std::cerr << "dyad bag filter: --end " << options.end_s << " is before --start " << options.start_s << "\n";
    return kBadInput;
  }
  auto r = bag::FilterRecording(in, out, options, std::cerr);
  if (!r.ok()) {
    std::cerr << "dyad bag filter: " << r.status().message() << "\n";
    return r.status().code() == Status::Code::kInvalidArgument ? kBadInput : kFailure;
  }
  std::cout << "wrote " << out << ": " << r->kept << " messages";
  if (!options.topics.empty() || options.start_s > 0 || options.end_s >= 0) std::cout << " (of the recording's, chosen)";
  std::cout << "\n";
  return kOk;
}

}  // namespace

void AddBagCommands(CLI::App& app, int& exit_code) {
  CLI::App* bag = app.add_subcommand("bag", "Inspect and export MCAP recordings");
  bag->require_subcommand(1);

  struct InfoArgs {
    std::string file;
    bool scan = false;
  };
  auto info_args = std::make_shared<InfoArgs>();
  CLI::App* info = bag->add_subcommand("info", "Channels, counts, time range, chunks and metadata of a recording");
  info->add_option("FILE", info_args->file, "MCAP file")->required();
  info->add_flag("--scan", info_args->scan, "Ignore the summary and scan the file record by record");
  info->callback([info_args, &exit_code] { exit_code = tools::Code(RunInfo(info_args->file, info_args->scan)); });

  struct ExportArgs {
    std::string file;
    std::string csv_dir;
    std::vector<std::string> topics;
  };
  auto export_args = std::make_shared<ExportArgs>();
  CLI::App* exp = bag->add_subcommand("export", "Write one CSV per channel");
  exp->add_option("FILE", export_args->file, "MCAP file")->required();
  exp->add_option("--csv", export_args->csv_dir, "Output directory (created if missing)")->required();
  exp->add_option("--topic", export_args->topics, "Only this topic (repeatable)");
  exp->callback([export_args, &exit_code] {
    exit_code = tools::Code(RunExport(export_args->file, export_args->csv_dir, export_args->topics));
  });

  struct FilterArgs {
    std::string in, out;
    bag::FilterOptions options;
  };
  auto filter_args = std::make_shared<FilterArgs>();
  CLI::App* filter = bag->add_subcommand("filter", "Copy some topics and a time window of a recording into a new MCAP file");
  filter->add_option("FILE", filter_args->in, "MCAP file")->required();
  filter->add_option("-o,--output", filter_args->out, "The new MCAP file")->required();
  filter->add_option("--topics", filter_args->options.topics, "Only these topics (default: all)");
  filter->add_option("--start", filter_args->options.start_s, "Seconds after the first message to begin at (default 0)")
      ->check(CLI::NonNegativeNumber);
  filter->add_option("--end", filter_args->options.end_s, "Seconds after the first message to end at (default: the end)")
      ->check(CLI::NonNegativeNumber);
  filter->callback(
      [filter_args, &exit_code] { exit_code = tools::Code(RunFilter(filter_args->in, filter_args->out, filter_args->options)); });
}

}  // namespace dyad::cli
