// Foxglove WebSocket protocol messages: the bytes we send, the client messages we accept, and
// every malformed one refused with a reason (never a throw).
#include "foxglove_protocol.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace dyad::web::foxglove {
namespace {

using json = nlohmann::json;

TEST(FoxgloveProtocol, AdvertiseNamesEncodingSchemaAndIds) {
  const json j = json::parse(Advertise({Channel{1, "robot/state", "dyad::msg::CartesianState", "module dyad {};"}}));
  EXPECT_EQ(j["op"], "advertise");
  ASSERT_EQ(j["channels"].size(), 1u);
  EXPECT_EQ(j["channels"][0]["id"], 1);
  EXPECT_EQ(j["channels"][0]["topic"], "robot/state");
  EXPECT_EQ(j["channels"][0]["encoding"], "cdr");
  EXPECT_EQ(j["channels"][0]["schemaEncoding"], "omgidl");
  EXPECT_EQ(j["channels"][0]["schemaName"], "dyad::msg::CartesianState");
  EXPECT_EQ(j["channels"][0]["schema"], "module dyad {};");
}

TEST(FoxgloveProtocol, ServerInfoSaysClientPublishOnlyWhenAllowed) {
  EXPECT_TRUE(json::parse(ServerInfo("x", false, "1", {}))["capabilities"].empty());
  EXPECT_EQ(json::parse(ServerInfo("x", true, "1", {}))["capabilities"][0], "clientPublish");
  EXPECT_EQ(json::parse(ServerInfo("x", true, "1", {}))["supportedEncodings"][0], "cdr");
}

TEST(FoxgloveProtocol, MessageDataIsOpcodeSubscriptionStampPayloadLittleEndian) {
  const uint8_t payload[] = {0, 1, 0, 0, 42};
  const std::string f = MessageData(0x01020304, 0x1122334455667788ull, payload);
  ASSERT_EQ(f.size(), 1u + 4 + 8 + 5);
  const std::string expect_head("\x01\x04\x03\x02\x01\x88\x77\x66\x55\x44\x33\x22\x11", 13);
  EXPECT_EQ(f.substr(0, 13), expect_head);
  EXPECT_EQ(f.substr(13), std::string("\0\1\0\0\x2a", 5));
}

TEST(FoxgloveProtocol, ParsesSubscribeAndUnsubscribe) {
  auto s = ParseClientText(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":2}]})");
  ASSERT_TRUE(s.ok()) << s.status().message();
  const auto& sub = std::get<Subscribe>(*s);
  ASSERT_EQ(sub.subscriptions.size(), 1u);
  EXPECT_EQ(sub.subscriptions[0], std::make_pair(7u, 2u));
  auto u = ParseClientText(R"({"op":"unsubscribe","subscriptionIds":[7]})");
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(std::get<Unsubscribe>(*u).subscription_ids, std::vector<uint32_t>{7});
}

TEST(FoxgloveProtocol, ParsesClientAdvertiseAndBinaryData) {
  auto a = ParseClientText(R"({"op":"advertise","channels":[{"id":3,"topic":"t","encoding":"cdr","schemaName":"S"}]})");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(std::get<ClientAdvertise>(*a).channels[0].topic, "t");
  const uint8_t frame[] = {1, 3, 0, 0, 0, 9, 9};
  auto d = ParseClientBinary(frame);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->channel_id, 3u);
  EXPECT_EQ(d->payload.size(), 2u);
}

TEST(FoxgloveProtocol, UnknownOpIsWellFormed) {
  auto o = ParseClientText(R"({"op":"getParameters","parameterNames":[]})");
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(std::get<OtherOp>(*o).op, "getParameters");
}

TEST(FoxgloveProtocol, MalformedTextIsRefusedWithAReason) {
  const std::pair<const char*, const char*> cases[] = {
      {"{", "not valid JSON"},
      {"[1,2]", "not a JSON object"},
      {R"({"op":3})", "no \"op\" string"},
      {R"({"op":"subscribe"})", "no \"subscriptions\" array"},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]})", "unsigned"},
      {R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":2}]})", "unsigned"},
      {R"({"op":"subscribe","subscriptions":[7]})", "unsigned"},
      {R"({"op":"unsubscribe","subscriptionIds":["a"]})", "unsigned 32-bit"},
      {R"({"op":"advertise","channels":[{"id":1}]})", "needs \"id\", \"topic\" and \"encoding\""},
      {R"({"op":"unadvertise"})", "no \"channelIds\" array"},
  };
  for (const auto& [text, why] : cases) {
    auto r = ParseClientText(text);
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.status().message().find(why), std::string::npos) << text << " -> " << r.status().message();
  }
}

// A frame of nested brackets is refused before parsing (nlohmann::json recurses per level: a
// 1 MiB frame of '[' would overflow a server thread's stack).
TEST(FoxgloveProtocol, DeepNestingIsRefusedWithoutParsing) {
  auto r = ParseClientText(std::string(1 << 20, '['));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("nested deeper than 32 levels"), std::string::npos) << r.status().message();
  // Brackets inside strings do not count.
  auto ok = ParseClientText(R"({"op":"subscribe","subscriptions":[],"note":")" + std::string(100, '[') + R"("})");
  EXPECT_TRUE(ok.ok()) << ok.status().message();
}

TEST(FoxgloveProtocol, MalformedBinaryIsRefusedWithAReason) {
  EXPECT_FALSE(ParseClientBinary({}).ok());
  const uint8_t wrong_op[] = {2, 0, 0, 0, 0};
  EXPECT_NE(ParseClientBinary(wrong_op).status().message().find("opcode 2"), std::string::npos);
  const uint8_t short_frame[] = {1, 0, 0};
  EXPECT_NE(ParseClientBinary(short_frame).status().message().find("shorter"), std::string::npos);
}

}  // namespace
}  // namespace dyad::web::foxglove
