#include "csv_export.hpp"

#include <filesystem>
#include <fstream>
#include <memory>

namespace dyad::bag {
namespace {

// Quotes a cell when it holds a separator, a quote or a line break (RFC 4180).
void PutCell(std::ostream& out, const std::string& cell) {
  if (cell.find_first_of(",\"\r\n") == std::string::npos) {
    out << cell;
    return;
  }
  out << '"';
  for (char c : cell) {
    if (c == '"') out << '"';
    out << c;
  }
  out << '"';
}

struct ChannelOutput {
  std::ofstream file;
  std::string path;
  PayloadDecoder decoder;
  std::vector<std::string> cells;  // The last row's payload cells, reused by the next.
  std::uint64_t rows = 0;
};

}  // namespace

PayloadDecoder HexDecoder() {
  return {{"data_hex"}, [](std::span<const std::uint8_t> data, std::vector<std::string>* cells) {
            static constexpr char kDigits[] = "0123456789abcdef";
            cells->resize(1);
            std::string& hex = (*cells)[0];
            hex.resize(data.size() * 2);
            for (std::size_t i = 0; i < data.size(); ++i) {
              hex[2 * i] = kDigits[data[i] >> 4];
              hex[2 * i + 1] = kDigits[data[i] & 0xF];
            }
            return Status::OK();
          }};
}

std::string FileNameForTopic(const std::string& topic) {
  std::string name;
  for (char c : topic) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                      c == '.' || c == '_';
    name += keep ? c : '_';
  }
  const auto first = name.find_first_not_of('_');  // "/robot/pose" -> "robot_pose"
  name = first == std::string::npos ? "" : name.substr(first);
  return name.empty() ? "topic" : name;
}

Status ExportCsv(const mcap::Reader& reader, const std::string& dir, const CsvExportOptions& options,
                 CsvExportSummary* summary) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return Status::IOError(dir, "cannot create directory: " + ec.message());

  std::map<mcap::ChannelId, std::unique_ptr<ChannelOutput>> outputs;
  std::set<std::string> used_names;
  for (const auto& [id, channel] : reader.channels()) {
    if (!options.topics.empty() && !options.topics.count(channel.topic)) continue;
    auto out = std::make_unique<ChannelOutput>();
    auto schema = reader.schemas().find(channel.schema_id);
    const mcap::Schema* schema_ptr = schema == reader.schemas().end() ? nullptr : &schema->second;
    std::optional<PayloadDecoder> decoder;
    if (options.decoder_factory) decoder = options.decoder_factory(schema_ptr, channel);
    out->decoder = decoder ? std::move(*decoder) : HexDecoder();

    std::string name = FileNameForTopic(channel.topic);
    if (!used_names.insert(name).second) name.append(1, '_').append(std::to_string(id));
    used_names.insert(name);
    out->path = (std::filesystem::path(dir) / (name + ".csv")).string();
    out->file.open(out->path, std::ios::out | std::ios::trunc);
    if (!out->file) return Status::IOError(out->path, "cannot open for writing");
    out->file << "log_time,publish_time,sequence";
    for (const std::string& column : out->decoder.columns) {
      out->file << ',';
      PutCell(out->file, column);
    }
    out->file << '\n';
    summary->files[channel.topic] = out->path;
    outputs.emplace(id, std::move(out));
  }

  mcap::ReadOptions read;
  read.topics = options.topics;
  read.skip_damaged = true;
  read.skipped_chunks = &summary->skipped_chunks;
  Status status = reader.ReadMessages(read, [&](const mcap::MessageView& m) {
    ChannelOutput& out = *outputs.at(m.channel->id);
    std::vector<std::string>& cells = out.cells;
    out.file << m.log_time << ',' << m.publish_time << ',' << m.sequence;
    const Status decoded = out.decoder.decode(m.data, &cells);
    if (!decoded.ok() || cells.size() != out.decoder.columns.size()) {
      if (summary->undecodable++ == 0) {
        summary->first_decode_error = m.channel->topic + " seq " + std::to_string(m.sequence) + ": " +
                                      (decoded.ok() ? "decoder returned the wrong number of cells" : decoded.message());
      }
      cells.assign(out.decoder.columns.size(), "");
    }
    for (const std::string& cell : cells) {
      out.file << ',';
      PutCell(out.file, cell);
    }
    out.file << '\n';
    ++out.rows;
    return true;
  });
  for (auto& [id, out] : outputs) {
    out->file.close();
    if (!out->file) return Status::IOError(out->path, "write failed");
    summary->rows[reader.channels().at(id).topic] = out->rows;
  }
  return status;
}

}  // namespace dyad::bag
