#include "recording_tables.hpp"

#include <cerrno>
#include <cstdlib>

#include "dyad/cdr_decoder.hpp"

namespace dyad::analyze {

int TopicTable::Column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return static_cast<int>(i);
  }
  return -1;
}

StatusOr<std::map<std::string, TopicTable>> ReadTables(const mcap::Reader& reader,
                                                       const std::set<std::string>& topics) {
  struct Decoder {
    cdr::Schema schema;
    std::string type;
    std::string topic;
  };
  std::map<mcap::ChannelId, Decoder> decoders;
  std::map<std::string, TopicTable> tables;
  for (const auto& [id, channel] : reader.channels()) {
    if (!topics.empty() && topics.count(channel.topic) == 0) continue;
    auto schema = reader.schemas().find(channel.schema_id);
    if (schema == reader.schemas().end() || schema->second.encoding != "omgidl") continue;
    StatusOr<cdr::Schema> parsed = cdr::Schema::Parse(schema->second.data);
    if (!parsed.ok() || !parsed->HasType(schema->second.name)) {
      return Status::DataLoss(reader.path() + ": topic " + channel.topic,
                              "its IDL schema \"" + schema->second.name + "\" does not parse: " +
                                  (parsed.ok() ? "type not defined" : parsed.status().message()));
    }
    tables[channel.topic].columns = cdr::Columns(*parsed, schema->second.name);
    decoders.emplace(id, Decoder{*parsed, schema->second.name, channel.topic});
  }
  mcap::ReadOptions options;
  for (const auto& [id, decoder] : decoders) options.topics.insert(decoder.topic);
  if (options.topics.empty()) return tables;
  Status failure = Status::OK();
  Status read = reader.ReadMessages(options, [&](const mcap::MessageView& m) {
    auto it = decoders.find(m.channel->id);
    if (it == decoders.end()) return true;
    TopicTable& table = tables[it->second.topic];
    table.rows.emplace_back();
    const Status decoded =
        cdr::DecodeRow(it->second.schema, it->second.type, m.data.data(), m.data.size(), &table.rows.back());
    if (!decoded.ok()) {
      failure = decoded.WithContext(reader.path() + ": topic " + it->second.topic + ": message " +
                                    std::to_string(table.rows.size()) + " does not decode");
      return false;
    }
    return true;
  });
  if (!read.ok()) return read;
  if (!failure.ok()) return failure;
  return tables;
}

std::string GraphMetadata(const mcap::Reader& reader, const std::string& key) {
  for (const mcap::Metadata& m : reader.metadata()) {
    if (m.name != "dyad.graph") continue;
    auto it = m.entries.find(key);
    if (it != m.entries.end()) return it->second;
  }
  return {};
}

bool ParseNumber(const std::string& cell, double* value) {
  if (cell.empty()) return false;
  errno = 0;
  char* end = nullptr;
  *value = std::strtod(cell.c_str(), &end);
  return errno == 0 && end == cell.c_str() + cell.size();
}

bool ParseBool(const std::string& cell, bool* value) {
  if (cell == "true" || cell == "1") { *value = true; return true; }
  if (cell == "false" || cell == "0") { *value = false; return true; }
  return false;
}

bool ParseNumberList(const std::string& cell, std::vector<double>* values) {
  values->clear();
  if (cell.size() < 2 || cell.front() != '[' || cell.back() != ']') return false;
  const char* p = cell.c_str() + 1;
  const char* last = cell.c_str() + cell.size() - 1;
  if (p == last) return true;
  while (p < last) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (end == p || errno != 0) return false;
    values->push_back(v);
    p = end;
    if (p < last && *p != ',') return false;
    if (p < last) ++p;
  }
  return true;
}

}  // namespace dyad::analyze
