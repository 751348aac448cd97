/// The Foxglove WebSocket protocol (`foxglove.websocket.v1`, also negotiated as
/// `foxglove.sdk.v1`): the messages dyad's bridge sends and the client messages it accepts.
/// Pure functions over bytes and JSON text, no sockets: the web server frames and sends them.
///
/// Server -> client: serverInfo, advertise, status (JSON text frames); Message Data (binary:
/// opcode 0x01, u32 subscription id, u64 timestamp ns, payload; little-endian).
/// Client -> server: subscribe, unsubscribe, advertise, unadvertise (JSON); Client Message Data
/// (binary: opcode 0x01, u32 client channel id, payload).
/// Parsing never throws: malformed input gives InvalidArgument naming what is wrong.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <dyad/status.hpp>

namespace dyad::web::foxglove {

inline constexpr const char* kSubprotocol = "foxglove.websocket.v1";
inline constexpr const char* kSubprotocolSdk = "foxglove.sdk.v1";

struct Channel {
  uint32_t id = 0;
  std::string topic;
  std::string schema_name;  // scoped IDL name, e.g. dyad::msg::CartesianState
  std::string schema;       // self-contained OMG IDL text
};

enum class Level { kInfo = 0, kWarning = 1, kError = 2 };

std::string ServerInfo(const std::string& name, bool client_publish, const std::string& session_id,
                       const std::vector<std::pair<std::string, std::string>>& metadata);
std::string Advertise(const std::vector<Channel>& channels);
std::string StatusMessage(Level level, const std::string& message);
// The binary Message Data frame for one sample: its CDR bytes with encapsulation, as is.
std::string MessageData(uint32_t subscription_id, uint64_t timestamp_ns, std::span<const uint8_t> payload);
// Its 13-byte head (opcode, subscription id, stamp): the bridge sends head + one shared payload.
std::string MessageDataHead(uint32_t subscription_id, uint64_t timestamp_ns);

struct Subscribe {
  std::vector<std::pair<uint32_t, uint32_t>> subscriptions;  // (subscription id, channel id)
};
struct Unsubscribe {
  std::vector<uint32_t> subscription_ids;
};
struct ClientChannel {
  uint32_t id = 0;
  std::string topic, encoding, schema_name;
};
struct ClientAdvertise {
  std::vector<ClientChannel> channels;
};
struct ClientUnadvertise {
  std::vector<uint32_t> channel_ids;
};
struct OtherOp {  // well-formed, but an op this server does not implement
  std::string op;
};
using ClientText = std::variant<Subscribe, Unsubscribe, ClientAdvertise, ClientUnadvertise, OtherOp>;

StatusOr<ClientText> ParseClientText(std::string_view json);

struct ClientMessageData {
  uint32_t channel_id = 0;
  std::span<const uint8_t> payload;  // into the frame given to ParseClientBinary
};
StatusOr<ClientMessageData> ParseClientBinary(std::span<const uint8_t> frame);

}  // namespace dyad::web::foxglove
