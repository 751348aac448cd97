#include "bag_filter.hpp"

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "dyad/mcap/reader.hpp"
#include "dyad/mcap/writer.hpp"

namespace dyad::bag {
namespace {

namespace fs = std::filesystem;

std::string Joined(const std::set<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", s);
  return buf;
}

}  // namespace

StatusOr<FilterResult> FilterRecording(const std::string& in, const std::string& out, const FilterOptions& o, std::ostream& log) {
  std::error_code ec;
  if (fs::weakly_canonical(in, ec) == fs::weakly_canonical(out, ec))
    return Status::InvalidArgument(out, "the output must be another file than the recording");
  auto reader = mcap::Reader::Open(in);
  if (!reader.ok()) return reader.status();
  if (reader->recovery().truncated) log << "dyad bag filter: " << in << ": " << reader->recovery().Describe() << "\n";
  std::set<std::string> present;
  for (const auto& [id, c] : reader->channels()) present.insert(c.topic);
  for (const auto& t : o.topics)
    if (!present.count(t)) return Status::InvalidArgument(in, "has no topic '" + t + "' (it has: " + Joined(present) + ")");

  // The first message's log time: the origin of --start and --end.
  uint64_t first = 0;
  if (Status s = reader->ReadMessages({}, [&](const mcap::MessageView& m) {
        first = m.log_time;
        return false;
      });
      !s.ok())
    return s;
  mcap::ReadOptions read;
  read.topics = std::set<std::string>(o.topics.begin(), o.topics.end());
  read.start_time = first + static_cast<uint64_t>(std::llround(std::max(0.0, o.start_s) * 1e9));
  if (o.end_s >= 0) read.end_time = first + static_cast<uint64_t>(std::llround(o.end_s * 1e9));

  const std::string tmp = out + ".tmp";
  auto writer = mcap::Writer::Open(tmp);
  if (!writer.ok()) return writer.status();
  std::map<mcap::ChannelId, mcap::ChannelId> channel_of;  // the recording's -> the output's
  FilterResult result;
  Status failed;
  auto copy = [&](const mcap::MessageView& m) {
    ++result.read;
    auto it = channel_of.find(m.channel->id);
    if (it == channel_of.end()) {
      mcap::SchemaId schema = 0;
      if (auto s = reader->schemas().find(m.channel->schema_id); s != reader->schemas().end()) {
        auto added = writer->AddSchema(s->second.name, s->second.encoding, s->second.data);
        if (!added.ok()) return failed = added.status(), false;
        schema = *added;
      }
      auto channel = writer->AddChannel(m.channel->topic, m.channel->message_encoding, schema, m.channel->metadata);
      if (!channel.ok()) return failed = channel.status(), false;
      it = channel_of.emplace(m.channel->id, *channel).first;
    }
    if (Status s = writer->Write(it->second, m.sequence, m.log_time, m.publish_time, m.data); !s.ok()) return failed = s, false;
    ++result.kept;
    return true;
  };
  Status s = reader->ReadMessages(read, copy);
  if (s.ok()) s = failed;
  for (const auto& md : reader->metadata())
    if (s.ok()) s = writer->AddMetadata(md.name, md.entries);
  if (s.ok())
    s = writer->AddMetadata("dyad.filter", {{"source", in},
                                            {"topics", o.topics.empty() ? "all" : Joined({o.topics.begin(), o.topics.end()})},
                                            {"start_s", Seconds(o.start_s)},
                                            {"end_s", o.end_s < 0 ? "end" : Seconds(o.end_s)}});
  if (Status c = writer->Close(); s.ok()) s = c;
  if (s.ok()) fs::rename(tmp, out, ec);
  if (s.ok() && ec) s = Status::IOError(out, "cannot rename " + tmp + ": " + ec.message());
  if (!s.ok()) {
    fs::remove(tmp, ec);
    return s;
  }
  return result;
}

}  // namespace dyad::bag
