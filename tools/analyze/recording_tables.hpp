// tools/analyze/recording_tables.hpp: a recording's topics as in-memory tables of decoded cells,
// for analysis code that wants columns by name rather than CDR bytes.
//
// Each table holds one row per message (log-time order) and the columns of the IDL-driven CDR
// decoder (dyad/cdr_decoder.hpp): "header.stamp_ns", "x", "engaged", sequences as one cell holding
// a JSON array of numbers ("[0.25,0.75]"). Only channels with an omgidl schema are read.
//
// Errors: a channel whose schema does not parse, or a payload that does not decode, fails the
// whole read with DataLoss naming the topic; damaged chunks fail (callers that want partial
// recordings use `dyad bag export`, which skips them).
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "dyad/mcap/reader.hpp"
#include "dyad/status.hpp"

namespace dyad::analyze {

struct TopicTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;

  // Index of `name` in columns, -1 when absent.
  int Column(const std::string& name) const;
  size_t size() const { return rows.size(); }
};

// Reads the listed topics (all topics when empty). A listed topic missing from the recording is
// simply absent from the result: analyses say which inputs they lacked.
StatusOr<std::map<std::string, TopicTable>> ReadTables(const mcap::Reader& reader,
                                                       const std::set<std::string>& topics);

// A value the recorder stored about the graph (metadata "dyad.graph"): "yaml" (the graph as
// run), "folder" (what its relative paths are relative to), "name", "clock"; empty when absent.
std::string GraphMetadata(const mcap::Reader& reader, const std::string& key);

// Cell parsers: a number ("nan" allowed), a bool ("true"/"false"), a JSON array of numbers.
// They return false on text that is not one.
bool ParseNumber(const std::string& cell, double* value);
bool ParseBool(const std::string& cell, bool* value);
bool ParseNumberList(const std::string& cell, std::vector<double>* values);

}  // namespace dyad::analyze
