// dyad/private_file.hpp: modes, exclusive creation, planted symlinks, replacement.
#include "dyad/private_file.hpp"

#include <gtest/gtest.h>

#include "dyad/testing/child_process.hpp"
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace dyad {
namespace {

class PrivateFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_private_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static std::string Read(const fs::path& p) { return testing::ReadFile(p); }
  static void WriteAndClose(int fd, const std::string& text) {
    ASSERT_EQ(write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
    close(fd);
  }
  static fs::perms Mode(const fs::path& p) { return fs::symlink_status(p).permissions() & fs::perms::all; }
  fs::path dir_;
};

TEST_F(PrivateFileTest, NewFilesAre0600InFoldersCreated0700) {
  const fs::path f = dir_ / "P01" / "trial1" / "run.mcap";
  EXPECT_FALSE(CreatePrivateFile(f.string(), CreateMode::kNew).ok());  // creates no folder
  EXPECT_FALSE(fs::exists(dir_ / "P01"));
  ASSERT_TRUE(CreatePrivateDirectories(f.parent_path().string()).ok());
  auto fd = CreatePrivateFile(f.string(), CreateMode::kNew);
  ASSERT_TRUE(fd.ok()) << fd.status().message();
  WriteAndClose(*fd, "data");
  EXPECT_EQ(Mode(f), fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(Mode(dir_ / "P01"), fs::perms::owner_all);
  EXPECT_EQ(Mode(dir_ / "P01" / "trial1"), fs::perms::owner_all);
  ASSERT_TRUE(CreatePrivateDirectories((dir_ / "g").string(), {.group_readable = true}).ok());
  auto group = CreatePrivateFile((dir_ / "g" / "x").string(), CreateMode::kNew, {.group_readable = true});
  ASSERT_TRUE(group.ok());
  close(*group);
  EXPECT_EQ(Mode(dir_ / "g" / "x"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(Mode(dir_ / "g"), fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec);
}

TEST_F(PrivateFileTest, WritePrivateFileWritesAllOfItOnceAndReplacesOnlyWhenAsked) {
  const fs::path f = dir_ / "key.pem";
  const std::string big(1 << 20, 'k');  // more than one write() may take
  ASSERT_TRUE(WritePrivateFile(f.string(), big, CreateMode::kNew).ok());
  EXPECT_EQ(Read(f), big);
  EXPECT_EQ(Mode(f), fs::perms::owner_read | fs::perms::owner_write);
  const Status again = WritePrivateFile(f.string(), "other", CreateMode::kNew);
  EXPECT_FALSE(again.ok());
  EXPECT_NE(again.message().find(": exists"), std::string::npos) << again.message();
  EXPECT_EQ(Read(f), big);
  ASSERT_TRUE(WritePrivateFile(f.string(), "other", CreateMode::kReplace).ok());
  EXPECT_EQ(Read(f), "other");
}

TEST_F(PrivateFileTest, AnExistingFileIsAnErrorAndKeepsItsContent) {
  const fs::path f = dir_ / "run.mcap";
  std::ofstream(f) << "earlier recording";
  auto fd = CreatePrivateFile(f.string(), CreateMode::kNew);
  ASSERT_FALSE(fd.ok());
  EXPECT_EQ(fd.status().message(),
            f.string() + ": exists: a file of 17 bytes (a private file is never opened through an existing entry)");
  EXPECT_EQ(Read(f), "earlier recording");
}

TEST_F(PrivateFileTest, APlantedSymlinkIsRefusedAndItsTargetUntouched) {
  const fs::path target = dir_ / "victim", link = dir_ / "run.mcap";
  std::ofstream(target) << "precious";
  fs::create_symlink(target, link);
  auto fd = CreatePrivateFile(link.string(), CreateMode::kNew);
  ASSERT_FALSE(fd.ok());
  // The refusal says what is there: the link and where it points.
  EXPECT_EQ(fd.status().message(), link.string() + ": exists: a symbolic link to '" + target.string() +
                                       "' (a private file is never opened through an existing entry)");
  auto log = OpenPrivateLog(link.string());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().message(), link.string() + ": is a symbolic link to '" + target.string() +
                                        "': refused (it could point anywhere)");
  fs::create_directory(dir_ / "a_folder");
  auto folder = CreatePrivateFile((dir_ / "a_folder").string(), CreateMode::kNew);
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.status().message().find("a_folder: exists: a folder"), std::string::npos) << folder.status().message();
  // A dangling link too (O_CREAT would have created its target).
  const fs::path dangling = dir_ / "dangling";
  fs::create_symlink(dir_ / "would_be_created", dangling);
  EXPECT_FALSE(CreatePrivateFile(dangling.string(), CreateMode::kNew).ok());
  EXPECT_FALSE(OpenPrivateLog(dangling.string()).ok());
  EXPECT_FALSE(fs::exists(dir_ / "would_be_created"));
  EXPECT_EQ(Read(target), "precious");
}

// Replacing: the entry is replaced, never written through: a link's target keeps its content.
TEST_F(PrivateFileTest, ReplaceSwapsTheEntryAndNeverWritesThroughALink) {
  const fs::path target = dir_ / "victim", link = dir_ / "run.mcap", plain = dir_ / "old.mcap";
  std::ofstream(target) << "precious";
  fs::create_symlink(target, link);
  std::ofstream(plain) << "old";
  fs::permissions(plain, fs::perms::all);
  for (const fs::path& p : {link, plain}) {
    auto fd = CreatePrivateFile(p.string(), CreateMode::kReplace);
    ASSERT_TRUE(fd.ok()) << fd.status().message();
    WriteAndClose(*fd, "new");
    EXPECT_FALSE(fs::is_symlink(p));
    EXPECT_EQ(Read(p), "new");
    EXPECT_EQ(Mode(p), fs::perms::owner_read | fs::perms::owner_write);
  }
  EXPECT_EQ(Read(target), "precious");
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 3u);  // victim, run.mcap, old.mcap: no temporary left behind
}

TEST_F(PrivateFileTest, ALogIsAppendedToAndKeepsTheModeItHad) {
  const fs::path f = dir_ / "mind.log";
  for (const char* line : {"one\n", "two\n"}) {
    auto fd = OpenPrivateLog(f.string());
    ASSERT_TRUE(fd.ok()) << fd.status().message();
    WriteAndClose(*fd, line);
  }
  EXPECT_EQ(Read(f), "one\ntwo\n");
  EXPECT_EQ(Mode(f), fs::perms::owner_read | fs::perms::owner_write);
}

TEST_F(PrivateFileTest, AFileWhereAFolderShouldBeIsNamed) {
  std::ofstream(dir_ / "P01") << "not a folder";
  const Status s = CreatePrivateDirectories((dir_ / "P01").string());
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message(), (dir_ / "P01").string() + ": is not a folder");
  EXPECT_FALSE(CreatePrivateDirectories((dir_ / "P01" / "trial1").string()).ok());
}

}  // namespace
}  // namespace dyad
