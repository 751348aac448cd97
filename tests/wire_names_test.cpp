// Opaque names on the wire (dyad/wire_names.hpp): the same name gives the same text under one
// key, the graph's participants read it back, nobody else does, and nothing of the name shows.
#include <dyad/wire_names.hpp>

#include "dds/dds_participant.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <sys/stat.h>
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
  // Names up to 47 bytes look alike; a longer one takes the second size; one over 143 bytes has
  // no wire name at all (its participant is refused: never a name its peers cannot read).
  EXPECT_EQ(WireName(kKey, "dyad/g/a").size(), WireName(kKey, "dyad/a_much_longer_graph_name/process").size());
  const std::string longer(60, 'x'), longest(150, 'y');
  EXPECT_GT(WireName(kKey, longer).size(), WireName(kKey, "dyad/g/a").size());
  EXPECT_EQ(ReadableName(kKey, WireName(kKey, longer)), longer);
  EXPECT_EQ(WireName(kKey, longest), "");
  EXPECT_EQ(WireName(kKey, std::string(kMaxReadableName + 1, 'y')), "");
  // A certificate's common name holds 64 characters.
  EXPECT_LE(WireSubject(kKey, longest).size(), 64u);
  EXPECT_EQ(WireName(kKey, "dyad/g/a").rfind(WireSubject(kKey, "dyad/g/a"), 0), 0u);
}

TEST(WireNames, TheLongestParticipantNameIsReadBack) {
  // A graph name and a process name may each have 64 characters: dyad/<graph>/<process> is 134
  // bytes, and its peers must still read it back (dyad param, pub's wait, topics --graph).
  const std::string name = "dyad/" + std::string(64, 'g') + "/" + std::string(64, 'p');
  const std::string wire = WireName(kKey, name);
  EXPECT_LT(wire.size(), 256u) << "a DDS participant name holds 255 characters";
  EXPECT_EQ(ReadableName(kKey, wire), name);
  EXPECT_EQ(wire.find("ggg"), std::string::npos) << wire;
  // dyad/launcher/<host> with a host of 64 characters, the longest a graph takes (graph.cpp).
  const std::string launcher = "dyad/launcher/" + std::string(64, 'h');
  EXPECT_EQ(ReadableName(kKey, WireName(kKey, launcher)), launcher);
  const std::string largest(kMaxReadableName, 'z');
  EXPECT_LT(WireName(kKey, largest).size(), 256u);
  EXPECT_EQ(ReadableName(kKey, WireName(kKey, largest)), largest);
}

// A participant whose name has no wire name is refused when it is made, saying why, never made
// with a name its peers cannot read (the graph's own names always fit: graph.cpp asserts it).
TEST(WireNames, ASecuredParticipantWithANameTooLongIsRefused) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("wire_names_long_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / kNamesKeyFile) << NewNamesKeyText().value();
  std::filesystem::permissions(dir / kNamesKeyFile, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  DdsParticipant::Options options;
  options.scope = DdsParticipant::Scope::kProcessOnly;
  options.security.identity_ca = (dir / "identity_ca.cert.pem").string();  // its folder holds names.key
  options.security.certificate = (dir / "never_read.cert.pem").string();
  const std::string name = "dyad/launcher/" + std::string(kMaxReadableName + 1 - 14, 'h');
  auto p = DdsParticipant::Create(0, name, options);
  ASSERT_FALSE(p.ok()) << "made with a name its peers cannot read back";
  EXPECT_NE(p.status().message().find("has 144 bytes: a secured graph's peers read back names of at most 143"), std::string::npos)
      << p.status().message();
  std::filesystem::remove_all(dir);
}

TEST(WireNames, TheKeyFileIsReadOrRefusedNamingIt) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("wire_names_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  auto text = NewNamesKeyText();
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(text.value().size(), 65u);
  EXPECT_NE(NewNamesKeyText().value(), text.value()) << "drawn, not fixed";
  std::ofstream(dir / "names.key") << text.value();
  std::filesystem::permissions(dir / "names.key", std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto key = ReadNamesKey((dir / "names.key").string());
  ASSERT_TRUE(key.ok()) << key.status().message();
  EXPECT_EQ(key.value().size(), 32u);
  std::ofstream(dir / "bad.key") << "not hex at all";
  std::filesystem::permissions(dir / "bad.key", std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto bad = ReadNamesKey((dir / "bad.key").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find((dir / "bad.key").string() + ": not a names key"), std::string::npos);
  auto missing = ReadNamesKey((dir / "none.key").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("run `dyad security init`"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// Read as a private file: never through a link (a link to /dev/zero would never end), never a
// special file, never one others can read, never more than a key's length.
TEST(WireNames, TheKeyFileIsPrivateAndSmall) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("wire_names_private_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const auto owner_only = std::filesystem::perms::owner_read | std::filesystem::perms::owner_write;
  auto refusal = [&](const std::string& file) {
    auto key = ReadNamesKey((dir / file).string());
    return key.ok() ? std::string("read") : key.status().message();
  };
  const std::string text = NewNamesKeyText().value();
  std::ofstream(dir / "open.key") << text;
  std::filesystem::permissions(dir / "open.key", owner_only | std::filesystem::perms::group_read);
  EXPECT_NE(refusal("open.key").find((dir / "open.key").string() + ": the names key readable by others (mode 0640"),
            std::string::npos)
      << refusal("open.key");
  std::filesystem::create_symlink("/dev/zero", dir / "zero.key");
  EXPECT_NE(refusal("zero.key").find((dir / "zero.key").string() + ": a symbolic link"), std::string::npos)
      << refusal("zero.key");
  std::filesystem::create_symlink(dir / "open.key", dir / "link.key");
  EXPECT_NE(refusal("link.key").find("a symbolic link"), std::string::npos) << refusal("link.key");
  ASSERT_EQ(mkfifo((dir / "fifo.key").c_str(), 0600), 0);
  EXPECT_NE(refusal("fifo.key").find((dir / "fifo.key").string() + ": not a regular file"), std::string::npos)
      << refusal("fifo.key");
  std::ofstream(dir / "long.key") << text << std::string(1 << 20, 'a');
  std::filesystem::permissions(dir / "long.key", owner_only);
  EXPECT_NE(refusal("long.key").find(": not a names key"), std::string::npos) << refusal("long.key");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dyad
