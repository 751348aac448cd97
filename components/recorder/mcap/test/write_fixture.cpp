// Writes the recordings that the Node test (@mcap/core) reads back, with the JSON it must find.
//
//   dyad_mcap_write_fixture OUT_DIR
// writes OUT_DIR/{full.mcap, full.expected.json, cut.mcap, cut.expected.json}:
//   full.mcap: 3 channels x 10,000 messages, two omgidl schemas, cdr, zstd chunks closing at
//              32 KiB (dozens of chunks), a "dyad.graph" metadata record holding YAML.
//   cut.mcap:  the same data with a Flush() every 1,000 messages, cut in the middle of chunk 13:
//              exactly the first 12,000 messages are complete.
// The expected JSON uses read_mcap.mjs's keys: counts, first/last log times and sequences,
// sequence gaps, and per channel the sum of the CRC32 of every payload.
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "dyad/mcap/writer.hpp"

namespace {

using dyad::mcap::ChannelId;
using dyad::Status;
using dyad::mcap::Writer;
using dyad::mcap::WriterOptions;

constexpr int kPerChannel = 10000;
constexpr std::uint64_t kStart = 1'700'000'000'000'000'000ull;  // 2023, in ns: beyond 2^53.

const char* const kPoseIdl =
    "module dyad {\n  module msg {\n    struct Pose2 {\n      unsigned long long stamp_ns;\n"
    "      double x;\n      double y;\n    };\n  };\n};\n";
const char* const kLabelIdl =
    "module dyad {\n  module msg {\n    struct IntentionLabel {\n      unsigned long long stamp_ns;\n"
    "      float congruence;\n      octet primitive;\n    };\n  };\n};\n";
const char* const kGraphYaml =
    "# demo graph\nnodes:\n  - id: recorder\n    type: recorder\n    params:\n"
    "      topics: [\"/human/pose\", '/robot/pose']\n      path: \"runs/\\\\demo.mcap\"\n";

std::string Json(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

struct ChannelSpec {
  const char* topic;
  const char* schema;
  std::size_t payload_size;
};
const ChannelSpec kChannels[3] = {{"/human/pose", "dyad::msg::Pose2", 28},
                                  {"/robot/pose", "dyad::msg::Pose2", 28},
                                  {"/observer/intention", "dyad::msg::IntentionLabel", 20}};

struct Tally {
  std::uint64_t count = 0, first = 0, last = 0, checksum = 0, bytes = 0;
};

std::vector<std::uint8_t> Payload(std::uint32_t i, std::size_t size) {
  std::vector<std::uint8_t> data(size);
  data[1] = 0x01;  // CDR little-endian encapsulation.
  for (std::size_t k = 4; k < size; ++k) data[k] = static_cast<std::uint8_t>(i * 13 + k * k + (i >> 5));
  return data;
}

// Writes the recording; `flush_every` > 0 also records bytes_written() after each Flush().
bool WriteRecording(const std::string& path, const WriterOptions& options, int flush_every,
                    std::vector<std::uint64_t>* flush_ends, std::vector<Tally>* tallies_at_flush) {
  auto writer = Writer::Open(path, options);
  if (!writer.ok()) return std::cerr << writer.status().ToString() << "\n", false;
  auto pose = writer->AddSchema("dyad::msg::Pose2", "omgidl", kPoseIdl);
  auto label = writer->AddSchema("dyad::msg::IntentionLabel", "omgidl", kLabelIdl);
  if (!pose.ok() || !label.ok()) return false;
  ChannelId ids[3];
  for (int c = 0; c < 3; ++c) {
    auto id = writer->AddChannel(kChannels[c].topic, "cdr", c < 2 ? *pose : *label, {{"index", std::to_string(c)}});
    if (!id.ok()) return std::cerr << id.status().ToString() << "\n", false;
    ids[c] = *id;
  }
  if (Status s = writer->AddMetadata("dyad.graph", {{"yaml", kGraphYaml}, {"name", "demo"}}); !s.ok()) return false;
  std::vector<Tally> tally(3);
  for (std::uint32_t i = 0; i < 3 * kPerChannel; ++i) {
    const int c = static_cast<int>(i % 3);
    const std::uint64_t log_time = kStart + i * 333'333ull;
    const auto data = Payload(i, kChannels[c].payload_size);
    if (Status s = writer->Write(ids[c], i / 3, log_time, log_time - 50'000, data); !s.ok()) {
      return std::cerr << s.ToString() << "\n", false;
    }
    Tally& t = tally[c];
    if (t.count == 0) t.first = log_time;
    t.last = log_time;
    ++t.count;
    t.checksum += crc32(0, data.data(), static_cast<uInt>(data.size()));
    t.bytes += data.size();
    if (flush_every > 0 && (i + 1) % flush_every == 0) {
      if (!writer->Flush().ok()) return false;
      flush_ends->push_back(writer->bytes_written());
      tallies_at_flush->insert(tallies_at_flush->end(), tally.begin(), tally.end());
    }
  }
  if (flush_every == 0) tallies_at_flush->assign(tally.begin(), tally.end());
  Status s = writer->Close();
  if (!s.ok()) std::cerr << s.ToString() << "\n";
  return s.ok();
}

bool WriteExpected(const std::string& path, const std::vector<Tally>& tally, bool complete) {
  std::ofstream out(path);
  std::uint64_t total = 0;
  for (const Tally& t : tally) total += t.count;
  out << "{\n  \"complete\": " << (complete ? "true" : "false") << ",\n  \"profile\": \"\",\n"
      << "  \"message_count\": " << total << ",\n"
      << "  \"first_log_time\": \"" << tally[0].first << "\",\n"
      << "  \"last_log_time\": \"" << std::max({tally[0].last, tally[1].last, tally[2].last}) << "\",\n"
      << "  \"schemas\": [\n"
      << "    {\"id\": 1, \"name\": \"dyad::msg::Pose2\", \"encoding\": \"omgidl\", \"data\": " << Json(kPoseIdl) << "},\n"
      << "    {\"id\": 2, \"name\": \"dyad::msg::IntentionLabel\", \"encoding\": \"omgidl\", \"data\": " << Json(kLabelIdl) << "}\n"
      << "  ],\n  \"channels\": [\n";
  for (int c = 0; c < 3; ++c) {
    const Tally& t = tally[c];
    out << "    {\"id\": " << c + 1 << ", \"topic\": " << Json(kChannels[c].topic)
        << ", \"message_encoding\": \"cdr\", \"schema_name\": " << Json(kChannels[c].schema)
        << ", \"count\": " << t.count << ", \"first_log_time\": \"" << t.first << "\", \"last_log_time\": \""
        << t.last << "\", \"first_sequence\": 0, \"last_sequence\": " << t.count - 1
        << ", \"sequence_gaps\": 0, \"duplicate_sequences\": 0, \"checksum\": \"" << t.checksum
        << "\", \"bytes\": " << t.bytes << "}" << (c < 2 ? ",\n" : "\n");
  }
  out << "  ],\n  \"metadata\": [\n    {\"name\": \"dyad.graph\", \"entries\": {\"name\": \"demo\", \"yaml\": "
      << Json(kGraphYaml) << "}}\n  ]\n}\n";
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: dyad_mcap_write_fixture OUT_DIR\n";
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);

  WriterOptions options;
  options.chunk_size = 32 * 1024;
  std::vector<std::uint64_t> unused;
  std::vector<Tally> full;
  if (!WriteRecording(dir / "full.mcap", options, 0, &unused, &full)) return 1;
  if (!WriteExpected(dir / "full.expected.json", full, true)) return 1;

  // Chunks delimited by Flush() only, so their boundaries are known; cut inside chunk 13.
  options.chunk_size = 1 << 20;
  constexpr int kFlushEvery = 1000, kCompleteChunks = 12;
  std::vector<std::uint64_t> ends;
  std::vector<Tally> at_flush;
  const std::string cut = dir / "cut.mcap";
  if (!WriteRecording(cut, options, kFlushEvery, &ends, &at_flush)) return 1;
  const std::uint64_t cut_at = (ends[kCompleteChunks - 1] + ends[kCompleteChunks]) / 2;
  std::filesystem::resize_file(cut, cut_at);
  std::vector<Tally> expected(at_flush.begin() + 3 * (kCompleteChunks - 1), at_flush.begin() + 3 * kCompleteChunks);
  if (!WriteExpected(dir / "cut.expected.json", expected, false)) return 1;
  std::cout << "wrote " << (dir / "full.mcap").string() << " and " << cut << " (cut at byte " << cut_at << ")\n";
  return 0;
}
