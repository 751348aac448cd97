// One participant's session of `dyad study serve`, from their session log alone (no network, no
// graph): the consent page, the waiting page with its Ready, the next attempt and why it repeats,
// the completion code made once, a restart that goes on where they were, and the connection's clock.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "online_session.hpp"
#include "online_study_fixture.hpp"
#include "study_session.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using namespace std::chrono_literals;

class OnlineSessionTest : public testing::OnlineStudyTest {
 protected:
  OnlineSessionTest() : OnlineStudyTest("dyad_online_") {}
  Json Frame(OnlineSession& s) { return Json::parse(s.PageFrame()); }
  // A start and, unless `outcome` is empty, an end of trial `trial` attempt `attempt`, as RunAttempt logs them.
  void Logged(int trial, int attempt, const std::string& outcome, const std::string& incomplete = "") {
    const Trial t = study_.TrialsOf("P01")[static_cast<size_t>(trial - 1)];
    ASSERT_TRUE(AppendSessionEvent(
                    study_, "P01",
                    Json{{"event", "start"}, {"trial", trial}, {"attempt", attempt}, {"file", AttemptFile(t, attempt)}}.dump())
                    .ok());
    std::ofstream(AttemptFile(t, attempt)) << "x";
    if (outcome.empty()) return;
    Json end = {{"event", "end"}, {"trial", trial}, {"attempt", attempt},           {"outcome", outcome},
                {"seconds", 3.0}, {"exit", 0},      {"ended", "exited with code 0"}};
    if (!incomplete.empty()) end["incomplete"] = incomplete;
    ASSERT_TRUE(AppendSessionEvent(study_, "P01", end.dump()).ok());
  }
};

TEST_F(OnlineSessionTest, ConsentThenEachTrialInOrderThenOneCodeKeptAcrossARestart) {
  OnlineSession s(study_, "P01");
  EXPECT_EQ(s.phase(), OnlineSession::Phase::kConsent);
  EXPECT_EQ(Frame(s), (Json{{"op", "consent"}, {"text", "Do you agree?"}}));
  EXPECT_FALSE(s.Next()) << "nothing starts before consent";
  ASSERT_TRUE(s.Consent(true).ok());
  EXPECT_TRUE(ReadSession(study_, "P01").consent);
  Json waiting = Frame(s);
  EXPECT_EQ(waiting["op"], "waiting");
  EXPECT_EQ(waiting["ready"]["label"], "Start trial 1 of 2");
  ASSERT_TRUE(s.Next());
  EXPECT_EQ(s.Next()->trial.number, 1);
  EXPECT_EQ(s.Next()->attempt, 1);
  EXPECT_EQ(s.Next()->reason, "");
  Logged(1, 1, "complete");
  EXPECT_EQ(Frame(s)["ready"]["label"], "Start trial 2 of 2");
  Logged(2, 1, "complete");
  EXPECT_EQ(s.phase(), OnlineSession::Phase::kDone);
  const Json done = Frame(s);
  EXPECT_EQ(done["op"], "done");
  const std::string code = done["code"];
  EXPECT_EQ(code.size(), 10u);
  EXPECT_EQ(code.find_first_not_of("ABCDEFGHJKLMNPQRSTUVWXYZ23456789"), std::string::npos) << code;
  // A restarted server: a new session object reads the same code back; it is logged once.
  OnlineSession again(study_, "P01");
  EXPECT_EQ(Frame(again)["code"], code);
  std::ifstream log(SessionLogPath(study_, "P01"));
  int completed = 0;
  for (std::string line; std::getline(log, line);) completed += Json::parse(line)["event"] == "completed";
  EXPECT_EQ(completed, 1);
}

TEST_F(OnlineSessionTest, AnEarlierAttemptIsRepeatedWithTheReasonOfItsEnd) {
  study_.consent_required = false;
  OnlineSession s(study_, "P01");
  EXPECT_EQ(Frame(s)["op"], "waiting") << "no consent page when the study requires none";
  Logged(1, 1, "");  // started, never ended: the server died during it
  ASSERT_TRUE(s.Next());
  EXPECT_EQ(s.Next()->trial.number, 1);
  EXPECT_EQ(s.Next()->attempt, 2);
  EXPECT_EQ(s.Next()->reason, "the server restarted during attempt 1");
  EXPECT_EQ(WhyNotStart(ReadSession(study_, "P01"), study_.TrialsOf("P01"), 1, s.Next()->reason), "");
  EXPECT_NE(Frame(s)["message"].get<std::string>().find("starts again"), std::string::npos);
  Logged(1, 2, "incomplete", "the participant's connection was lost for more than 5 s");
  EXPECT_EQ(s.Next()->attempt, 3);
  EXPECT_EQ(s.Next()->reason, "attempt 2 was incomplete: the participant's connection was lost for more than 5 s");
  Logged(1, 3, "stopped");
  EXPECT_EQ(s.Next()->reason, "attempt 3 was stopped");
  Logged(1, 4, "failed");
  EXPECT_EQ(s.Next()->reason, "attempt 4 failed: the graph exited with code 0 after 3.0 s and left no whole recording");
  // A file in the way (a recording never logged) is never replaced: the next free number.
  std::ofstream(AttemptFile(study_.TrialsOf("P01")[0], 5)) << "x";
  EXPECT_EQ(s.Next()->attempt, 6);
}

TEST_F(OnlineSessionTest, DeclinedOrWithdrawnParticipantsAreRefusedAndTheFixedCodeIsEveryones) {
  OnlineSession s(study_, "P01");
  ASSERT_TRUE(s.Consent(false).ok());
  EXPECT_EQ(s.phase(), OnlineSession::Phase::kRefused);
  EXPECT_EQ(Frame(s)["op"], "refused");
  EXPECT_FALSE(s.Next());
  ASSERT_TRUE(WithdrawConsent(study_, "P01", false, "test").ok());
  EXPECT_NE(Frame(s)["message"].get<std::string>().find("withdrawn"), std::string::npos);
  EXPECT_FALSE(s.Consent(true).ok()) << "a withdrawn participant's new consent is marked in the lab only";
  study_.consent_required = false;
  study_.online.completion_code = "PROLIFIC1";
  study_.trials = 1;
  study_.conditions.resize(1);
  OnlineSession p2(study_, "P02");
  ASSERT_TRUE(AppendSessionEvent(study_, "P02", R"({"event":"start","trial":1,"attempt":1,"file":"f"})").ok());
  ASSERT_TRUE(AppendSessionEvent(study_, "P02", R"({"event":"end","trial":1,"attempt":1,"outcome":"complete"})").ok());
  EXPECT_EQ(Frame(p2), (Json{{"op", "done"}, {"message", Frame(p2)["message"]}, {"code", "PROLIFIC1"}}));
}

TEST_F(OnlineSessionTest, ThePageIsLostFromWhenItLeftAndTheSessionStaysLiveForReconnectS) {
  OnlineSession s(study_, "P01");
  const auto t0 = OnlineSession::Clock::now();
  EXPECT_FALSE(s.Live(t0, false)) << "a page never opened";
  EXPECT_TRUE(s.Live(t0, true)) << "a running trial is live";
  s.PageOpened();
  EXPECT_TRUE(s.page());
  EXPECT_EQ(s.LostFor(t0 + 100s), OnlineSession::Clock::duration::zero());
  s.PageClosed(t0);
  EXPECT_EQ(s.LostFor(t0 + 3s), std::chrono::duration_cast<OnlineSession::Clock::duration>(3s));
  EXPECT_TRUE(s.Live(t0 + 4s, false));
  EXPECT_FALSE(s.Live(t0 + 6s, false)) << "reconnect_s (5) after the page left between trials";
  s.PageOpened();
  EXPECT_EQ(s.LostFor(t0 + 10s), OnlineSession::Clock::duration::zero());
  s.PageFinished();  // done or refused: nothing to come back for
  EXPECT_FALSE(s.Live(t0 + 10s, false));
}

}  // namespace
}  // namespace dyad::study
