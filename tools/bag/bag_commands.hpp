// `dyad bag ...`: inspect and export MCAP recordings from the command line.
//
//   dyad bag info FILE [--scan]
//       Schemas, channels with message counts, time range, chunk count and compression, metadata
//       names and keys. A file cut short (killed recorder) is read by a linear scan; the report
//       says so and where the recovered part ends. --scan forces the scan even on intact files.
//   dyad bag export FILE --csv DIR [--topic T]...
//       One CSV per channel in DIR (created if missing): log_time,publish_time,sequence, then the
//       payload columns: one per field (dyad/cdr_decoder.hpp's Columns) when the channel's schema
//       is omgidl IDL text, else one `data_hex` column. Damaged chunks are skipped, payloads that
//       do not decode leave their cells empty, and an omgidl schema that does not parse falls back
//       to data_hex: each is reported on stderr and makes the exit code 1. A file cut short is
//       exported up to its last complete chunk, with a note on stderr (exit code 0).
//
// Each subcommand's callback stores its exit code in `exit_code`: 0 ok, 1 failure (cannot
// write, damaged data, undecodable schema or payload), 2 bad input (missing file, not an MCAP
// file, unknown --topic). Errors go to stderr as "dyad bag: FILE: what is wrong".
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

// Adds the `bag` command group to `app`. `exit_code` must outlive app.parse().
void AddBagCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
