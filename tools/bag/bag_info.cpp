#include "bag_info.hpp"

#include <cstdio>
#include <ctime>
#include <regex>
#include <map>
#include <sstream>

namespace dyad::bag {
namespace {

std::string Bytes(std::uint64_t n) {
  char text[32];
  if (n < 10 * 1024) std::snprintf(text, sizeof(text), "%llu B", static_cast<unsigned long long>(n));
  else if (n < 10ull * 1024 * 1024) std::snprintf(text, sizeof(text), "%.1f KiB", n / 1024.0);
  else std::snprintf(text, sizeof(text), "%.1f MiB", n / (1024.0 * 1024.0));
  return text;
}

}  // namespace

std::string FormatTime(std::uint64_t ns, bool simulated) {
  char text[96];
  if (simulated) {
    std::snprintf(text, sizeof(text), "%llu.%09llu (simulated time since start: stepped clock)",
                  static_cast<unsigned long long>(ns / 1'000'000'000ull), static_cast<unsigned long long>(ns % 1'000'000'000ull));
    return text;
  }
  const std::time_t seconds = static_cast<std::time_t>(ns / 1'000'000'000ull);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", &utc);
  std::snprintf(text, sizeof(text), "%llu.%09llu (%s)", static_cast<unsigned long long>(ns / 1'000'000'000ull),
                static_cast<unsigned long long>(ns % 1'000'000'000ull), date);
  return text;
}

std::string FormatInfo(const mcap::Reader& reader) {
  const mcap::Recovery& r = reader.recovery();
  const mcap::Statistics& s = reader.statistics();
  std::ostringstream out;
  out << "file:        " << reader.path() << " (" << r.file_size << " bytes)\n";
  out << "state:       " << r.Describe() << "\n";
  if (r.truncated && !r.data_complete) {
    out << "             (the counts below cover the recovered part only)\n";
  }
  out << "library:     " << (reader.header().library.empty() ? "(none)" : reader.header().library)
      << "; profile: " << (reader.header().profile.empty() ? "(none)" : reader.header().profile) << "\n";
  out << "messages:    " << s.message_count << "\n";
  if (s.message_count > 0) {
    const double span = (s.message_end_time - s.message_start_time) / 1e9;
    char duration[32];
    std::snprintf(duration, sizeof(duration), "%.3f s", span);
    // A stepped run's stamps count simulated time from 0: not dates (they read as 1970).
    bool stepped = false;
    for (const mcap::Metadata& m : reader.metadata()) {
      auto it = m.entries.find("yaml");
      if (m.name == "dyad.graph" && it != m.entries.end())
        stepped = std::regex_search(it->second, std::regex(R"((^|\n)clock:[ \t]*stepped\b)"));
    }
    out << "start:       " << FormatTime(s.message_start_time, stepped) << "\n";
    out << "end:         " << FormatTime(s.message_end_time, stepped) << "\n";
    out << "duration:    " << duration << "\n";
  }
  std::map<std::string, std::size_t> by_compression;
  std::uint64_t compressed = 0, uncompressed = 0;
  for (const mcap::ChunkInfo& c : reader.chunks()) {
    ++by_compression[c.compression.empty() ? "none" : c.compression];
    compressed += c.compressed_size;
    uncompressed += c.uncompressed_size;
  }
  out << "chunks:      " << reader.chunks().size();
  if (!reader.chunks().empty()) {
    out << " (";
    const char* sep = "";
    for (const auto& [name, count] : by_compression) {
      out << sep << name << ": " << count;
      sep = ", ";
    }
    char ratio[32];
    std::snprintf(ratio, sizeof(ratio), "%.2f", compressed ? static_cast<double>(uncompressed) / compressed : 0.0);
    out << "), " << Bytes(uncompressed) << " -> " << Bytes(compressed) << " (ratio " << ratio << ")";
  }
  out << "\n";
  if (!r.damaged_chunks.empty()) {
    out << "damaged:     " << r.damaged_chunks.size() << " chunk(s)\n";
    for (const auto& [offset, why] : r.damaged_chunks) out << "  at offset " << offset << ": " << why << "\n";
  }
  out << "schemas:     " << reader.schemas().size() << "\n";
  for (const auto& [id, schema] : reader.schemas()) {
    out << "  " << id << "  " << schema.name << "  [" << schema.encoding << ", " << schema.data.size() << " bytes]\n";
  }
  out << "channels:    " << reader.channels().size() << "\n";
  for (const auto& [id, channel] : reader.channels()) {
    auto count = s.channel_message_counts.find(id);
    auto schema = reader.schemas().find(channel.schema_id);
    out << "  " << id << "  " << channel.topic << "  "
        << (count == s.channel_message_counts.end() ? 0 : count->second) << " msgs  ["
        << channel.message_encoding << ", " << (schema == reader.schemas().end() ? "no schema" : schema->second.name)
        << "]\n";
  }
  out << "metadata:    " << reader.metadata().size() << "\n";
  for (const mcap::Metadata& m : reader.metadata()) {
    out << "  " << m.name << ":";
    const char* sep = " ";
    for (const auto& [key, value] : m.entries) {
      out << sep << key << " (" << value.size() << " bytes)";
      sep = ", ";
    }
    out << "\n";
  }
  if (r.loose_messages > 0) out << "note:        " << r.loose_messages << " messages outside chunks were not read\n";
  return out.str();
}

}  // namespace dyad::bag
