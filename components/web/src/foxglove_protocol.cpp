#include "foxglove_protocol.hpp"

#include <limits>

#include <nlohmann/json.hpp>

#include "json_limits.hpp"

namespace dyad::web::foxglove {
namespace {

using json = nlohmann::json;

void PutLe(std::string* out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

Status Bad(const std::string& what) { return Status::InvalidArgument(what); }

// A non-negative integer field that fits in uint32.
bool U32(const json& obj, const char* key, uint32_t* out) {
  auto it = obj.find(key);
  if (it == obj.end() || !it->is_number_unsigned()) return false;
  const uint64_t v = it->get<uint64_t>();
  if (v > std::numeric_limits<uint32_t>::max()) return false;
  *out = static_cast<uint32_t>(v);
  return true;
}
bool Str(const json& obj, const char* key, std::string* out) {
  auto it = obj.find(key);
  if (it == obj.end() || !it->is_string()) return false;
  *out = it->get<std::string>();
  return true;
}
const json* Array(const json& obj, const char* key) {
  auto it = obj.find(key);
  return it != obj.end() && it->is_array() ? &*it : nullptr;
}

}  // namespace

std::string ServerInfo(const std::string& name, bool client_publish, const std::string& session_id,
                       const std::vector<std::pair<std::string, std::string>>& metadata) {
  json m = json::object();
  for (const auto& [k, v] : metadata) m[k] = v;
  json j = {{"op", "serverInfo"},
            {"name", name},
            {"capabilities", client_publish ? json::array({"clientPublish"}) : json::array()},
            {"supportedEncodings", json::array({"cdr"})},
            {"metadata", m},
            {"sessionId", session_id}};
  return j.dump();
}

std::string Advertise(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const auto& c : channels)
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", "cdr"},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", "omgidl"}});
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string StatusMessage(Level level, const std::string& message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string MessageDataHead(uint32_t subscription_id, uint64_t timestamp_ns) {
  std::string out;
  out.push_back(0x01);
  PutLe(&out, subscription_id, 4);
  PutLe(&out, timestamp_ns, 8);
  return out;
}

std::string MessageData(uint32_t subscription_id, uint64_t timestamp_ns, std::span<const uint8_t> payload) {
  std::string out = MessageDataHead(subscription_id, timestamp_ns);
  out.append(reinterpret_cast<const char*>(payload.data()), payload.size());
  return out;
}

StatusOr<ClientText> ParseClientText(std::string_view text) {
  if (!JsonDepthWithin(text)) return Bad("nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  const json j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return Bad("not valid JSON");
  if (!j.is_object()) return Bad("not a JSON object");
  std::string op;
  if (!Str(j, "op", &op)) return Bad("no \"op\" string");
  if (op == "subscribe") {
    const json* subs = Array(j, "subscriptions");
    if (subs == nullptr) return Bad("subscribe: no \"subscriptions\" array");
    Subscribe s;
    for (const auto& e : *subs) {
      uint32_t id, channel;
      if (!e.is_object() || !U32(e, "id", &id) || !U32(e, "channelId", &channel))
        return Bad("subscribe: each subscription needs unsigned \"id\" and \"channelId\"");
      s.subscriptions.emplace_back(id, channel);
    }
    return ClientText(s);
  }
  if (op == "unsubscribe") {
    const json* ids = Array(j, "subscriptionIds");
    if (ids == nullptr) return Bad("unsubscribe: no \"subscriptionIds\" array");
    Unsubscribe u;
    for (const auto& e : *ids) {
      if (!e.is_number_unsigned() || e.get<uint64_t>() > std::numeric_limits<uint32_t>::max())
        return Bad("unsubscribe: subscription ids must be unsigned 32-bit integers");
      u.subscription_ids.push_back(e.get<uint32_t>());
    }
    return ClientText(u);
  }
  if (op == "advertise") {
    const json* chans = Array(j, "channels");
    if (chans == nullptr) return Bad("advertise: no \"channels\" array");
    ClientAdvertise a;
    for (const auto& e : *chans) {
      ClientChannel c;
      if (!e.is_object() || !U32(e, "id", &c.id) || !Str(e, "topic", &c.topic) || !Str(e, "encoding", &c.encoding))
        return Bad("advertise: each channel needs \"id\", \"topic\" and \"encoding\"");
      Str(e, "schemaName", &c.schema_name);
      a.channels.push_back(std::move(c));
    }
    return ClientText(a);
  }
  if (op == "unadvertise") {
    const json* ids = Array(j, "channelIds");
    if (ids == nullptr) return Bad("unadvertise: no \"channelIds\" array");
    ClientUnadvertise u;
    for (const auto& e : *ids) {
      if (!e.is_number_unsigned() || e.get<uint64_t>() > std::numeric_limits<uint32_t>::max())
        return Bad("unadvertise: channel ids must be unsigned 32-bit integers");
      u.channel_ids.push_back(e.get<uint32_t>());
    }
    return ClientText(u);
  }
  return ClientText(OtherOp{op});
}

StatusOr<ClientMessageData> ParseClientBinary(std::span<const uint8_t> frame) {
  if (frame.empty()) return Bad("empty binary frame");
  if (frame[0] != 0x01) return Bad("binary opcode " + std::to_string(frame[0]) + " is not Client Message Data (1)");
  if (frame.size() < 5) return Bad("Client Message Data shorter than its 5-byte header");
  ClientMessageData d;
  d.channel_id = static_cast<uint32_t>(frame[1]) | static_cast<uint32_t>(frame[2]) << 8 |
                 static_cast<uint32_t>(frame[3]) << 16 | static_cast<uint32_t>(frame[4]) << 24;
  d.payload = frame.subspan(5);
  return d;
}

}  // namespace dyad::web::foxglove
