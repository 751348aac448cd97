// The experimenter's overview of `dyad study serve` without a network or a graph: a session
// stopped between trials (logged with its reason, shown as ended, its page refused, kept across a
// restart, resumed), a trial graph's stats frame read, and DATA/serve-tokens made once and refused
// when others could read it. The browser test (overview_test.sh) covers a stop mid-trial.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "online_front.hpp"
#include "online_session.hpp"
#include "online_study_fixture.hpp"
#include "overview_channel.hpp"
#include "study_session.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

class OverviewTest : public testing::OnlineStudyTest {
 protected:
  OverviewTest() : OnlineStudyTest("dyad_overview_") {}
  void SetUp() override {
    OnlineStudyTest::SetUp();
    for (const std::string& p : study_.participants) EXPECT_TRUE(MarkConsent(study_, p, "in the test").ok());
  }
  Json LastLine(const std::string& p) {
    std::ifstream in(SessionLogPath(study_, p));
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return Json::parse(last);
  }
};

TEST_F(OverviewTest, ASessionStoppedBetweenTrialsIsLoggedShownEndedRefusedUntilResumed) {
  const auto now = OnlineFront::Clock::now();
  OnlineFront front(study_, FrontOptions{"dyad", 2});
  EXPECT_TRUE(front.Snapshot(now).empty()) << "no page has come: no live session";
  EXPECT_EQ(front.StopSession("P09", "x").code(), Status::Code::kNotFound);
  EXPECT_EQ(front.StopSession("P01", " \n").code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(LastLine("P01")["event"], "consent") << "a refused stop logs nothing";

  ASSERT_TRUE(front.StopSession("P01", "the participant is a bot").ok());
  const Json ended = LastLine("P01");
  EXPECT_EQ(ended["event"], "session_ended");
  EXPECT_EQ(ended["reason"], "the participant is a bot");
  auto views = front.Snapshot(now);
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].participant, "P01");
  EXPECT_EQ(views[0].phase, "ended");
  EXPECT_EQ(views[0].ended, "the participant is a bot");
  EXPECT_EQ(views[0].trial, 1);
  EXPECT_EQ(views[0].of, 2);
  EXPECT_EQ(views[0].shown, study_.Shown(study_.conditions[static_cast<size_t>(study_.TrialsOf("P01")[0].condition)]));
  EXPECT_TRUE(views[0].file.empty());
  EXPECT_FALSE(views[0].engaged.has_value());
  EXPECT_EQ(front.StopSession("P01", "again").code(), Status::Code::kFailedPrecondition);

  OnlineSession session(study_, "P01");
  const Json page = Json::parse(session.PageFrame());
  EXPECT_EQ(page["op"], "refused");
  EXPECT_EQ(page["message"], "The experimenter has ended this session. Thank you for your time.");
  EXPECT_EQ(session.phase(), OnlineSession::Phase::kRefused);

  {  // a restarted front reads the end from the log
    OnlineFront restarted(study_, FrontOptions{"dyad", 2});
    views = restarted.Snapshot(now);
    ASSERT_EQ(views.size(), 1u);
    EXPECT_EQ(views[0].ended, "the participant is a bot");
  }

  EXPECT_EQ(front.ResumeSession("P02").code(), Status::Code::kFailedPrecondition);
  ASSERT_TRUE(front.ResumeSession("P01").ok());
  EXPECT_EQ(LastLine("P01")["event"], "session_resumed");
  EXPECT_TRUE(front.Snapshot(now).empty());
  EXPECT_EQ(Json::parse(session.PageFrame())["op"], "waiting");
}

TEST_F(OverviewTest, ABlindStudyShowsTheConditionsLabel) {
  study_.blind = true;
  OnlineFront front(study_, FrontOptions{"dyad", 2});
  ASSERT_TRUE(front.StopSession("P02", "a reason").ok());
  const auto views = front.Snapshot(OnlineFront::Clock::now());
  ASSERT_EQ(views.size(), 1u);
  EXPECT_TRUE(views[0].shown == "condition A" || views[0].shown == "condition B") << views[0].shown;
}

TEST(OverviewStats, TheLargestP99AndTheMissesSummed) {
  const auto s = ParseStats(
      R"({"op":"stats","rows":[{"component":"web","process":"g","steps":90,"mean_ms":0.1,"p99_ms":0.4,"max_ms":1,"misses":1},)"
      R"({"component":"mind","process":"g","steps":30,"mean_ms":2,"p99_ms":7.5,"max_ms":9,"misses":2}]})");
  ASSERT_TRUE(s.has_value());
  EXPECT_DOUBLE_EQ(s->p99_ms, 7.5);
  EXPECT_EQ(s->component, "mind");
  EXPECT_EQ(s->misses, 3);
  EXPECT_FALSE(ParseStats(R"({"op":"stats","rows":[]})").has_value()) << "no stats yet";
  EXPECT_FALSE(ParseStats(R"({"op":"series","t":1})").has_value());
  EXPECT_FALSE(ParseStats("not json \"stats\"").has_value());
}

TEST_F(OverviewTest, TheServeTokenFileIsMadeOnceAndRefusedWhenOthersCanReadIt) {
  auto first = ServeExperimenterToken(study_);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  const std::string file = study_.data + "/serve-tokens";
  struct stat st {};
  ASSERT_EQ(stat(file.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto again = ServeExperimenterToken(study_);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(*again, *first);
  chmod(file.c_str(), 0644);
  auto readable = ServeExperimenterToken(study_);
  ASSERT_FALSE(readable.ok());
  EXPECT_NE(readable.status().message().find(file + ": holds the experimenter's overview token and is readable by others"),
            std::string::npos)
      << readable.status().message();
  fs::remove(file);
  fs::create_symlink(dir_ / "elsewhere", file);
  std::ofstream(dir_ / "elsewhere") << "experimenter 0123456789abcdef0123\n";
  fs::permissions(dir_ / "elsewhere", fs::perms::owner_read | fs::perms::owner_write);
  auto link = ServeExperimenterToken(study_);
  ASSERT_FALSE(link.ok());
  EXPECT_NE(link.status().message().find(file + ": not a regular file"), std::string::npos) << link.status().message();
  fs::remove(file);
  std::ofstream(file) << "experimenter short\n";
  fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write);
  auto bad = ServeExperimenterToken(study_);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(file + ": the experimenter's token is not 16..256"), std::string::npos);
}

}  // namespace
}  // namespace dyad::study
