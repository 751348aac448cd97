// Opaque names on the wire (dyad/wire_names.hpp): the same name gives the same text under one
// key, the graph's participants read it back, nobody else does, and nothing of the name shows.
#include <dyad/wire_names.hpp>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

namespace dyad {
namespace {

const std::string kKey(32, '\x5a');
const std::string kOtherKey(32, '\x17');

TEST(WireNames, AParticipantNameIsOpaqueStableAndReadBackOnlyWithItsKey) {
  const std::string name = "dyad/lab_graph/robot_arm";
  const std::string wire = WireName(kKey, name);
  EXPECT_EQ(wire.find("lab_graph"), std::string::npos) << wire;
  EXPECT_EQ(wire.find("robot"), std::string::npos) << wire;
  EXPECT_EQ(wire.rfind("dyad~", 0), 0u) << wire;
  EXPECT_LT(wire.size(), 256u) << "a DDS participant name holds 255 characters";
  EXPECT_EQ(WireName(kKey, name), wire) << "the same for every run";
  EXPECT_NE(WireName(kOtherKey, name), wire);
  EXPECT_EQ(ReadableName(kKey, wire), name);
  EXPECT_EQ(ReadableName(kOtherKey, wire), "") << "another graph's key reads nothing";
  EXPECT_EQ(ReadableName(kKey, name), "") << "a plain name is not one of ours";
  EXPECT_EQ(ReadableName(kKey, ""), "");
  // A forgery: one digit of the sealed name changed; the HMAC no longer vouches for it.
  std::string forged = wire;
  forged.back() = forged.back() == '0' ? '1' : '0';
  EXPECT_EQ(ReadableName(kKey, forged), "");
}

TEST(WireNames, LengthSaysLittleAndASubjectIsShort) {
  // Names up to 47 bytes look alike; a longer one takes the second size; 96 bytes or more: the
  // subject alone (not readable back).
  EXPECT_EQ(WireName(kKey, "dyad/g/a").size(), WireName(kKey, "dyad/a_much_longer_graph_name/process").size());
  const std::string longer(60, 'x'), longest(120, 'y');
  EXPECT_GT(WireName(kKey, longer).size(), WireName(kKey, "dyad/g/a").size());
  EXPECT_EQ(ReadableName(kKey, WireName(kKey, longer)), longer);
  EXPECT_EQ(WireName(kKey, longest), WireSubject(kKey, longest));
  EXPECT_EQ(ReadableName(kKey, WireName(kKey, longest)), "");
  // A certificate's common name holds 64 characters.
  EXPECT_LE(WireSubject(kKey, longest).size(), 64u);
  EXPECT_EQ(WireName(kKey, "dyad/g/a").rfind(WireSubject(kKey, "dyad/g/a"), 0), 0u);
}

TEST(WireNames, TheKeyFileIsReadOrRefusedNamingIt) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("wire_names_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  auto text = NewNamesKeyText();
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text.value().size(), 65u);
  EXPECT_NE(NewNamesKeyText().value(), text.value()) << "drawn, not fixed";
  std::ofstream(dir / "names.key") << text.value();
  auto key = ReadNamesKey((dir / "names.key").string());
  ASSERT_TRUE(key.ok()) << key.status().message();
  EXPECT_EQ(key.value().size(), 32u);
  std::ofstream(dir / "bad.key") << "not hex at all";
  auto bad = ReadNamesKey((dir / "bad.key").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find((dir / "bad.key").string() + ": not a names key"), std::string::npos);
  auto missing = ReadNamesKey((dir / "none.key").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("run `dyad security init`"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dyad
