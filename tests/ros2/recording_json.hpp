// The messages of a recording decoded by dyad's IDL-driven decoder, as JSON (test code only): how
// the ROS 2 tests read back what `dyad run` recorded, independently of the types' C++ code.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "dyad/cdr_decoder.hpp"
#include "dyad/mcap/reader.hpp"

namespace dyad::testing {

struct RecordedJson {
  std::string topic;
  int64_t t_ns = 0;  // log time
  nlohmann::json value;
};

// Every message of `topics` (empty: all) in log-time order; a message that does not decode fails
// the calling test.
inline std::vector<RecordedJson> ReadRecordingJson(const std::string& path, const std::set<std::string>& topics = {}) {
  std::vector<RecordedJson> out;
  auto reader = mcap::Reader::Open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().message();
  if (!reader.ok()) return out;
  mcap::ReadOptions options;
  options.topics = topics;
  const Status s = reader->ReadMessages(options, [&](const mcap::MessageView& m) {
    const mcap::Schema& schema = reader->schemas().at(m.channel->schema_id);
    auto parsed = cdr::Schema::Parse(schema.data);
    std::vector<cdr::Field> fields;
    const Status d = parsed.ok() ? cdr::Decode(*parsed, schema.name, m.data.data(), m.data.size(), &fields) : parsed.status();
    EXPECT_TRUE(d.ok()) << m.channel->topic << ": " << d.message();
    if (d.ok()) out.push_back({m.channel->topic, static_cast<int64_t>(m.log_time), nlohmann::json::parse(cdr::ToJson(fields))});
    return true;
  });
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

}  // namespace dyad::testing
