// SubjectChannel's answers to "What were you drawing?": only the steering page's, only when
// asked, only a primitive of the data set or -1, and a viewer's refused (it closes the page);
// its acks, through a WebServer to a WsClient: at most one per kAckIntervalMs.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "subject_channel.hpp"
#include "web_server.hpp"
#include "ws_client.hpp"

namespace dyad::web {
namespace {

struct Answers {
  std::vector<int> choices;
  SubjectChannel Channel(bool ask) {
    SubjectChannel::Options o;
    o.primitives.assign(7, {{0.0, 0.0}, {1.0, 1.0}});
    o.ask = ask;
    return SubjectChannel(o, [](double, double, bool) {}, [this](int c, int segment) {
      EXPECT_EQ(segment, -1) << "an answer after an event is about no question of the trial";
      choices.push_back(c);
      return Status::OK();
    });
  }
};

TEST(SubjectChannel, TheSteeringPagesAnswerReachesTheGraph) {
  Answers a;
  SubjectChannel ch = a.Channel(true);
  ch.OnOpen(1, Role::kSubject);  // steers: the first subject page
  ch.OnOpen(2, Role::kSubject);  // watches
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":6})").ok());
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":-1})").ok());
  ASSERT_TRUE(ch.OnText(2, R"({"op":"self_report","choice":3})").ok()) << "a watching page is ignored, not closed";
  EXPECT_EQ(a.choices, (std::vector<int>{6, -1}));
}

TEST(SubjectChannel, ABadAnswerOrAViewersIsRefused) {
  Answers a;
  SubjectChannel ch = a.Channel(true);
  ch.OnOpen(1, Role::kSubject);
  ch.OnOpen(3, Role::kViewer);
  for (const char* bad : {R"({"op":"self_report","choice":7})", R"({"op":"self_report","choice":-2})",
                          R"({"op":"self_report","choice":1.5})", R"({"op":"self_report"})", R"({"op":"self_report","choice":"2"})"}) {
    const Status s = ch.OnText(1, bad);
    EXPECT_EQ(s.code(), Status::Code::kInvalidArgument) << bad;
    EXPECT_NE(s.message().find("needs an integer \"choice\" in -1..6"), std::string::npos) << s.message();
  }
  const Status viewer = ch.OnText(3, R"({"op":"self_report","choice":1})");
  EXPECT_EQ(viewer.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(viewer.message().find("a viewer's token may not answer"), std::string::npos) << viewer.message();
  EXPECT_TRUE(a.choices.empty());
}

TEST(SubjectChannel, AnAnswerNobodyAskedForIsIgnored) {
  Answers a;
  SubjectChannel ch = a.Channel(false);  // the graph records no answers
  ch.OnOpen(1, Role::kSubject);
  EXPECT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":2})").ok());
  EXPECT_TRUE(a.choices.empty());
}

// self_reports: after_trial. Once the trial is over nobody steers (the hold under way ends, a
// later pointer sample is published released), and only the steering page's answer to the
// question shown counts: one answer per hold, in turn.
TEST(SubjectChannel, AfterTheTrialEachHoldIsAskedInTurnAndNobodySteers) {
  std::vector<bool> engaged;
  std::vector<std::pair<int, int>> answers;  // (choice, segment)
  SubjectChannel::Options o;
  o.primitives.assign(7, {{0.0, 0.0}, {1.0, 1.0}});
  SubjectChannel ch(o, [&](double, double, bool e) { engaged.push_back(e); }, [&](int c, int segment) {
    answers.push_back({c, segment});
    return Status::OK();
  });
  ch.OnOpen(1, Role::kSubject);  // steers
  ch.OnOpen(2, Role::kSubject);  // watches
  ch.OnOpen(3, Role::kViewer);
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":1,"segment":0})").ok());
  EXPECT_TRUE(answers.empty()) << "nothing is asked before the trial ends (and after_event is off)";
  ASSERT_TRUE(ch.OnText(1, R"({"op":"pointer","x":1,"y":2,"engaged":true})").ok());
  ch.EndSteering();
  ASSERT_TRUE(ch.OnText(1, R"({"op":"pointer","x":1,"y":2,"engaged":true})").ok());
  EXPECT_EQ(engaged, (std::vector<bool>{true, false, false})) << "the hold ends when the trial does; no steering after it";
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":1,"segment":0})").ok());
  EXPECT_TRUE(answers.empty()) << "steering ended, nothing asked yet";
  using Q = SubjectChannel::Question;
  ch.AskAfterTrial({Q{{{0, 0}, {1, 1}}, {}}, Q{{{2, 2}, {3, 3}}, {{2, 3}}}});
  EXPECT_EQ(engaged.size(), 3u) << "the steering had ended already: no second release";
  ch.AskAfterTrial({Q{{{9, 9}}, {}}});  // a second call changes nothing
  for (const char* ignored : {R"({"op":"self_report","choice":2})",               // no question named
                              R"({"op":"self_report","choice":2,"segment":1})"})  // not the one shown
    ASSERT_TRUE(ch.OnText(1, ignored).ok()) << ignored;
  ASSERT_TRUE(ch.OnText(2, R"({"op":"self_report","choice":2,"segment":0})").ok()) << "a watching page is ignored";
  EXPECT_EQ(ch.OnText(3, R"({"op":"self_report","choice":2,"segment":0})").code(), Status::Code::kFailedPrecondition);
  for (const char* bad : {R"({"op":"self_report","choice":2,"segment":-1})", R"({"op":"self_report","choice":2,"segment":"0"})",
                          R"({"op":"self_report","choice":2,"segment":0.5})"})
    EXPECT_EQ(ch.OnText(1, bad).code(), Status::Code::kInvalidArgument) << bad;
  EXPECT_TRUE(answers.empty());
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":3,"segment":0})").ok());
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":4,"segment":0})").ok());  // a second click: ignored
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":-1,"segment":1})").ok());
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":5,"segment":2})").ok());  // there is no third
  EXPECT_EQ(answers, (std::vector<std::pair<int, int>>{{3, 0}, {-1, 1}}));
}

// AskAfterTrial alone ends the steering too (the hold under way ends once), and with no holds
// to ask about an answer finds no question.
TEST(SubjectChannel, AskingAfterTheTrialEndsTheSteeringByItself) {
  std::vector<bool> engaged;
  int answers = 0;
  SubjectChannel::Options o;
  o.primitives.assign(7, {{0.0, 0.0}, {1.0, 1.0}});
  SubjectChannel ch(o, [&](double, double, bool e) { engaged.push_back(e); }, [&](int, int) {
    ++answers;
    return Status::OK();
  });
  ch.OnOpen(1, Role::kSubject);
  ASSERT_TRUE(ch.OnText(1, R"({"op":"pointer","x":1,"y":2,"engaged":true})").ok());
  ch.AskAfterTrial({});
  ASSERT_TRUE(ch.OnText(1, R"({"op":"pointer","x":1,"y":2,"engaged":true})").ok());
  ch.EndSteering();  // already ended: no second release
  EXPECT_EQ(engaged, (std::vector<bool>{true, false, false}));
  ASSERT_TRUE(ch.OnText(1, R"({"op":"self_report","choice":1,"segment":0})").ok());
  EXPECT_EQ(answers, 0);
}

// The experimenter opens /subject before the participant: the participant's page, once it
// comes, steers; the experimenter's stops (its hold ends: one disengaged sample), and steers again
// only when the participant's page leaves.
TEST(SubjectChannel, TheSubjectsPageSteersBeforeTheExperimenters) {
  std::vector<std::pair<int, bool>> published;  // (page whose pointer it was, engaged)
  int sender = 0;
  SubjectChannel ch(SubjectChannel::Options{}, [&](double, double, bool engaged) { published.push_back({sender, engaged}); });
  auto pointer = [&](web::ClientId c) {
    sender = static_cast<int>(c);
    return ch.OnText(c, R"({"op":"pointer","x":1,"y":2,"engaged":true})");
  };
  ch.OnOpen(1, Role::kExperimenter);
  ASSERT_TRUE(pointer(1).ok());
  ch.OnOpen(2, Role::kSubject);
  ch.OnOpen(3, Role::kSubject);  // a second subject page does not take over from the first
  ASSERT_TRUE(pointer(1).ok());  // ignored: not the steering page any more
  ASSERT_TRUE(pointer(3).ok());  // ignored
  ASSERT_TRUE(pointer(2).ok());
  EXPECT_EQ(published, (std::vector<std::pair<int, bool>>{{1, true}, {1, false}, {2, true}}));
  ch.OnClose(2);  // the subject's other page steers, not the experimenter's
  ASSERT_TRUE(pointer(3).ok());
  ASSERT_TRUE(pointer(1).ok());
  EXPECT_EQ(published.back(), (std::pair<int, bool>{3, true}));
}

bool Eventually(const std::function<bool()>& done) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// The "t" of each ack a page received, in order.
struct Acks {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<int> t;
  WsClient::Callbacks Callbacks() {
    return {[this](std::string_view text) {
              const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
              if (!j.is_object() || j.value("op", "") != "ack") return;
              std::lock_guard<std::mutex> lock(mutex);
              t.push_back(static_cast<int>(j.at("t").get<double>()));
              cv.notify_all();
            },
            {}};
  }
  // Every ack up to the one of sample `last`.
  std::vector<int> Until(int last) {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait_for(lock, std::chrono::seconds(10), [&] { return !t.empty() && t.back() == last; });
    return t;
  }
};

// The page's pointer at 60 Hz (15-18.5 ms apart, a browser's pointermove) for 1 s, then one
// sample after a pause, each "t" its index; the channel's clock is the test's, set per sample.
// Acked: the first sample and each one kAckIntervalMs or more after the last ack (the newest
// sample's then: an ack at most one frame interval late), about 10 in the second; the sample
// after the pause at once. Before the throttle every sample was acked (61 here).
TEST(SubjectChannel, APageGetsAtMostOneAckPer100MsAndTheFirstSampleAfterAPauseHasOne) {
  std::atomic<double> now_ms{0};
  std::atomic<int> published{0};
  SubjectChannel::Options o;
  o.wall_ms = [&] { return now_ms.load(); };
  SubjectChannel ch(o, [&](double, double, bool) { ++published; });
  WebServer::Options so;
  so.port = 0;
  so.tokens = {{Role::kSubject, "subject-token-0123456789"}};
  so.endpoints = {WebServer::Endpoint{"/subject/ws", {}, &ch, {Role::kSubject}, /*viewers=*/false}};
  auto server = WebServer::Start(so);
  ASSERT_TRUE(server.ok()) << server.status().ToString();
  ch.SetServer(server->get());
  Acks acks;
  auto page = WsClient::Connect("127.0.0.1", (*server)->port(), "/subject/ws?token=subject-token-0123456789", acks.Callbacks(),
                                std::chrono::seconds(5));
  ASSERT_TRUE(page.ok()) << page.status().ToString();
  ASSERT_TRUE(Eventually([&] { return ch.steered(); }));
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> interval(15, 18.5);
  std::vector<double> at;  // each sample's time, ms
  for (double t = 1.7e12; at.size() < 61; t += at.size() < 60 ? interval(rng) : 500) {
    const int i = static_cast<int>(at.size());
    at.push_back(t);
    now_ms = t;
    ASSERT_TRUE((*page)->SendText(R"({"op":"pointer","x":1,"y":2,"engaged":true,"t":)" + std::to_string(i) + "}").ok());
    ASSERT_TRUE(Eventually([&] { return published == i + 1; })) << "sample " << i << " not published";
  }
  ASSERT_GE(at[59] - at[0], 900);
  std::vector<int> expected;  // the rule: kAckIntervalMs or more since the last ack
  for (size_t i = 0; i < at.size(); i++)
    if (expected.empty() || at[i] - at[expected.back()] >= SubjectChannel::kAckIntervalMs)
      expected.push_back(static_cast<int>(i));
  const std::vector<int> got = acks.Until(60);
  EXPECT_EQ(got, expected);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), 60) << "the sample after the pause is acked at once";
  const size_t in_the_second = got.size() - 1;
  EXPECT_GE(in_the_second, 9u);
  EXPECT_LE(in_the_second, 11u) << "60 samples in a second, acked every 100 ms";
  for (size_t k = 1; k < in_the_second; k++) {
    const double gap = at[got[k]] - at[got[k - 1]];
    EXPECT_GE(gap, SubjectChannel::kAckIntervalMs) << "acks " << got[k - 1] << " and " << got[k];
    EXPECT_LE(gap, SubjectChannel::kAckIntervalMs + 18.5) << "acks " << got[k - 1] << " and " << got[k];
  }
  (*page)->Close();
}

}  // namespace
}  // namespace dyad::web
