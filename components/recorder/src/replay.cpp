#include "replay.hpp"

#include <map>
#include <memory>
#include <set>

#include <yaml-cpp/yaml.h>

#include <dyad/topic_select.hpp>

namespace dyad::recorder {
namespace {
// The MCAP library's messages start with the file's path; the param prefix already names it.
std::string Detail(const std::string& message, const std::string& path) {
  if (message.rfind(path + ": ", 0) == 0) return message.substr(path.size() + 2);
  return message;
}
}  // namespace

void Replay::Describe(ComponentSpec& spec) {
  spec.Summary("Republishes the topics of an MCAP recording with their original timing (wall) or one recorded instant per step (stepped).");
  spec.RequiredParam("file", ParamType::kString).Path().Doc("the MCAP recording to replay");
  spec.Param("topics", std::vector<std::string>{}).Doc("recorded topics, names or regexes; empty: all but dyad/stats");
  spec.YamlParam("remap", "{}").Doc("recorded topic -> topic to publish on, e.g. {human/input: replay/human}");
  spec.Param("speed", 1.0).Min(1e-6).Doc("wall clock: time scale (2 = twice as fast)");
  spec.Param("start_s", 0.0).Min(0).Unit("s").Doc("skip the first seconds of the recording (counted from its first chosen message)");
  spec.Param("loop", false).Doc("start over after the last message, until the run ends (no stop request)");
}

Status Replay::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  path_ = p.String("file");
  speed_ = p.Double("speed");
  loop_ = p.Bool("loop");
  auto reader = mcap::Reader::Open(path_);
  if (!reader.ok()) return Status::InvalidArgument("params.file = '" + path_ + "': " + Detail(reader.status().message(), path_));
  if (reader->recovery().truncated) ctx.log().Warn(reader->recovery().Describe());

  std::vector<std::string> recorded;
  std::map<std::string, const mcap::Channel*> by_topic;
  for (const auto& [id, ch] : reader->channels())
    if (by_topic.emplace(ch.topic, &ch).second) recorded.push_back(ch.topic);
  auto chosen = SelectTopics(p.StringList("topics"), recorded, "params.topics", {"dyad/stats"});
  if (!chosen.ok()) return chosen.status();
  if (chosen->empty()) return Status::InvalidArgument("params.topics: '" + path_ + "' holds no topic to replay");

  std::map<std::string, std::string> remap;
  YAML::Node node;
  try {
    node = YAML::Load(p.String("remap"));
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument(std::string("params.remap: not YAML: ") + e.what());
  }
  if (node && !node.IsNull() && !node.IsMap()) return Status::InvalidArgument("params.remap: must be a mapping {recorded topic: new topic}");
  if (node.IsMap())
    for (const auto& kv : node) {
      const std::string from = kv.first.Scalar();
      if (!kv.second.IsScalar() || kv.second.Scalar().empty())
        return Status::InvalidArgument("params.remap." + from + ": must be a topic name");
      if (std::find(chosen->begin(), chosen->end(), from) == chosen->end())
        return Status::InvalidArgument("params.remap." + from + ": not a replayed topic of '" + path_ + "'");
      remap[from] = kv.second.Scalar();
    }

  for (const auto& topic : *chosen) {
    const mcap::Channel& ch = *by_topic.at(topic);
    auto sit = reader->schemas().find(ch.schema_id);
    const std::string where = "params.file = '" + path_ + "': topic '" + topic + "'";
    if (sit == reader->schemas().end() || sit->second.encoding != "omgidl" || ch.message_encoding != "cdr")
      return Status::InvalidArgument(where + " is not omgidl/cdr: replay cannot publish it");
    const mcap::Schema& schema = sit->second;
    const TypeInfo* type = ctx.FindMessageType(schema.name);
    if (type == nullptr) return Status::NotFound(where + " carries " + schema.name + ", a type this process does not know");
    auto dds = ch.metadata.find("dds_type");
    const bool same = dds != ch.metadata.end() ? dds->second == type->dds_name() : schema.data == type->idl;
    if (!same)
      return Status::InvalidArgument(where + " was recorded with " + (dds != ch.metadata.end() ? dds->second : schema.name + " (other IDL)") +
                                     ", this build has " + type->dds_name() + ": the definitions differ");
    const std::string target = remap.count(topic) ? remap[topic] : topic;
    auto w = ctx.AdvertiseSerialized(target, *type);
    if (!w.ok()) return Status::InvalidArgument("params.remap: cannot publish '" + topic + "' on '" + target + "': " + w.status().message());
    topics_.push_back(topic);
    writers_.push_back(w.value());
  }

  // Load the chosen messages now: errors belong to Configure, and Step() then only publishes.
  std::map<std::string, uint32_t> writer_of;
  for (size_t i = 0; i < topics_.size(); ++i) writer_of[topics_[i]] = static_cast<uint32_t>(i);
  mcap::ReadOptions ro;
  ro.order = mcap::ReadOptions::Order::kLogTime;
  ro.topics = std::set<std::string>(topics_.begin(), topics_.end());
  Status s = reader->ReadMessages(ro, [&](const mcap::MessageView& m) {
    Message msg;
    msg.writer = writer_of.at(m.channel->topic);
    msg.log_time = m.log_time;
    msg.publish_time = m.publish_time;
    msg.offset = static_cast<uint32_t>(bytes_.size());
    msg.size = static_cast<uint32_t>(m.data.size());
    bytes_.insert(bytes_.end(), m.data.begin(), m.data.end());
    messages_.push_back(msg);
    return bytes_.size() < UINT32_MAX / 2;
  });
  if (!s.ok()) return Status::DataLoss("params.file = '" + path_ + "': " + Detail(s.message(), path_));
  if (bytes_.size() >= UINT32_MAX / 2) return Status::Unimplemented("params.file = '" + path_ + "': more than 2 GiB of chosen messages");
  if (Status s = SkipStart(p.Double("start_s")); !s.ok()) return s;
  ctx.log().Info("replaying " + std::to_string(messages_.size()) + " messages on " + std::to_string(topics_.size()) + " topic(s) from " + path_);
  return Status::OK();
}

// The first message played: the first `start_s` seconds of the recording are skipped.
Status Replay::SkipStart(double start_s) {
  begin_ = 0;
  if (messages_.empty()) return Status::OK();
  const double skip_ns = start_s * 1e9;
  const uint64_t first = messages_.front().log_time;
  while (begin_ < messages_.size() && static_cast<double>(messages_[begin_].log_time - first) < skip_ns) ++begin_;
  if (begin_ == messages_.size())
    return Status::InvalidArgument("params.start_s: " + std::to_string(start_s) + " s is past the last chosen message of '" + path_ + "'");
  return Status::OK();
}

Status Replay::Activate() {
  next_ = begin_;
  start_ns_ = -1;
  done_ = false;
  return Status::OK();
}

Status Replay::PublishUpTo(size_t end) {
  for (; next_ < end; ++next_) {
    const Message& m = messages_[next_];
    std::span<const uint8_t> data(bytes_.data() + m.offset, m.size);
    if (Status s = writers_[m.writer]->Write(data, static_cast<int64_t>(m.publish_time)); !s.ok()) return s;
  }
  return Status::OK();
}

Status Replay::Step(const StepInfo& info) {
  if (done_) return Status::OK();
  size_t end = next_;
  if (ctx_->stepped()) {
    // One recorded instant: every message with the next log time.
    if (end < messages_.size()) {
      const uint64_t t = messages_[end].log_time;
      while (end < messages_.size() && messages_[end].log_time == t) ++end;
    }
  } else {
    if (start_ns_ < 0) start_ns_ = info.now_ns;
    const double elapsed = static_cast<double>(info.now_ns - start_ns_) * speed_;
    const uint64_t first = messages_.empty() ? 0 : messages_[begin_].log_time;
    while (end < messages_.size() && static_cast<double>(messages_[end].log_time - first) <= elapsed) ++end;
  }
  if (Status s = PublishUpTo(end); !s.ok()) return s;
  if (next_ >= messages_.size() && loop_) {
    // The next pass starts at the next step (its first message then, as the first pass's did).
    next_ = begin_;
    start_ns_ = -1;
  } else if (next_ >= messages_.size()) {
    done_ = true;
    ctx_->RequestStop("replayed " + std::to_string(messages_.size()) + " messages from " + path_);
  }
  return Status::OK();
}

}  // namespace dyad::recorder
