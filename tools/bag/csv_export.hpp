// `dyad bag export --csv`: one CSV file per channel, with a pluggable payload decoder.
//
// Each CSV starts with the header `log_time,publish_time,sequence,<payload columns>` and has one
// row per message in log-time order; times are integer nanoseconds. The payload columns come from
// a PayloadDecoder chosen per channel by CsvExportOptions::decoder_factory; without one (or when
// it declines a channel) the payload is one `data_hex` column. `dyad bag export` plugs in the
// IDL-driven CDR decoder (dyad/cdr_decoder.hpp) for omgidl schemas: see bag_commands.cpp.
//
// Usage:
//   dyad::bag::CsvExportOptions options;
//   options.decoder_factory = [&](const dyad::mcap::Schema* schema, const dyad::mcap::Channel&)
//       -> std::optional<dyad::bag::PayloadDecoder> {
//     if (schema == nullptr || schema->encoding != "omgidl") return std::nullopt;  // -> hex
//     return MakeMyDecoder(*schema);  // columns: stamp_ns, x, y, ...
//   };
//   dyad::bag::CsvExportSummary summary;
//   dyad::Status s = dyad::bag::ExportCsv(reader, "out/", options, &summary);
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "dyad/mcap/reader.hpp"
#include "dyad/status.hpp"

namespace dyad::bag {

struct PayloadDecoder {
  // Header names of the payload columns (at least one).
  std::vector<std::string> columns;
  // Replaces *cells with exactly columns.size() cells for `data`, or returns why it cannot. *cells holds the previous row of the same channel: assign into its strings rather than
  // clearing it, so a row costs no allocation once they have grown. Cells are written as given,
  // CSV-quoted when needed.
  std::function<Status(std::span<const std::uint8_t> data, std::vector<std::string>* cells)> decode;
};

// Picks the decoder for a channel; `schema` is null when the channel has none. nullopt -> hex.
using DecoderFactory =
    std::function<std::optional<PayloadDecoder>(const mcap::Schema* schema, const mcap::Channel& channel)>;

// The fallback decoder: one column `data_hex`, lowercase hex of the payload.
PayloadDecoder HexDecoder();

struct CsvExportOptions {
  // Default: null, every channel exported as hex.
  DecoderFactory decoder_factory;
  // Only these topics; empty means all.
  std::set<std::string> topics;
};

struct CsvExportSummary {
  std::map<std::string, std::string> files;  // topic -> CSV path written
  std::map<std::string, std::uint64_t> rows;  // topic -> rows written
  std::uint64_t undecodable = 0;             // Messages whose payload cells were left empty.
  std::string first_decode_error;            // e.g. "/robot/pose seq 12: payload too short".
  std::uint64_t skipped_chunks = 0;          // Damaged chunks skipped.
};

// Writes DIR/<topic>.csv for each chosen channel ("/robot/pose" -> "robot_pose.csv"; the
// channel id is appended when two topics would share a name). Creates `dir` if missing.
// Damaged chunks are skipped and counted rather than failing the export.
// Fails: IOError naming the CSV that cannot be written; errors of Reader::ReadMessages.
Status ExportCsv(const mcap::Reader& reader, const std::string& dir, const CsvExportOptions& options,
                 CsvExportSummary* summary);

// "robot_pose" for "/robot/pose": letters, digits, '-', '.', '_' kept, the rest '_'.
std::string FileNameForTopic(const std::string& topic);

}  // namespace dyad::bag
