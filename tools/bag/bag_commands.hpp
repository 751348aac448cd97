// `dyad bag ...`: inspect and export MCAP recordings from the command line.
//
//   dyad bag info FILE [--scan]
//       Schemas, channels with message counts, time range, chunk count and compression, metadata
//       names and keys. A file cut short (killed recorder) is read by a linear scan; the report
//       says so and where the recovered part ends. --scan forces the scan even on intact files.
//   dyad bag export FILE --csv DIR [--topic T]...
//       One CSV per channel in DIR (created if missing): log_time,publish_time,sequence, then the
//       payload columns (for now `data_hex`; see csv_export.hpp for per-schema decoders).
//
// Each subcommand's callback stores its exit code in `exit_code`: 0 ok, 1 failure (cannot
// write, damaged data), 2 bad input (missing file, not an MCAP file).
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

// Adds the `bag` command group to `app`. `exit_code` must outlive app.parse().
void AddBagCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
