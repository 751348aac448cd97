// The experimenter's page's requests (ExperimenterChannel): live parameter requests checked for
// their shape and role before they reach the sink; answers listed for the page (ParamAnswers).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "experimenter_channel.hpp"
#include "param_answers.hpp"

namespace dyad::web {
namespace {

class ExperimenterChannelTest : public ::testing::Test {
 protected:
  ExperimenterChannelTest()
      : channel_([this](const std::string& text) { notes_.push_back(text); },
                 [this](const ParamRequest& r) -> StatusOr<std::string> {
                   asked_.push_back(r);
                   return "id-" + std::to_string(asked_.size());
                 }) {
    channel_.OnOpen(kExperimenter, Role::kExperimenter);
    channel_.OnOpen(kViewer, Role::kViewer);
  }
  static constexpr ClientId kExperimenter = 1, kViewer = 2;
  std::vector<std::string> notes_;
  std::vector<ParamRequest> asked_;
  ExperimenterChannel channel_;
};

TEST_F(ExperimenterChannelTest, ASetAndAGetReachTheSinkParsed) {
  EXPECT_TRUE(channel_.OnText(kExperimenter, R"({"op":"param","name":"mixer.gain","value":"0.5"})").ok());
  EXPECT_TRUE(channel_.OnText(kExperimenter, R"({"op":"param","name":"mind.meta_prior"})").ok());
  // Split at the first dot (the process refuses a parameter it does not have); a value is any
  // YAML text up to 4 KiB, checked by the component's process.
  EXPECT_TRUE(channel_.OnText(kExperimenter, R"({"op":"param","name":"mind.a.b","value":"[1, 2]"})").ok());
  const std::string longest = std::string(4096, '9');
  EXPECT_TRUE(channel_.OnText(kExperimenter, R"({"op":"param","name":"mixer.max_step","value":")" + longest + R"("})").ok());
  ASSERT_EQ(asked_.size(), 4u);
  EXPECT_EQ(asked_[0], (ParamRequest{"mixer", "gain", true, "0.5"}));
  EXPECT_EQ(asked_[1], (ParamRequest{"mind", "meta_prior", false, ""}));
  EXPECT_EQ(asked_[2], (ParamRequest{"mind", "a.b", true, "[1, 2]"}));
  EXPECT_EQ(asked_[3], (ParamRequest{"mixer", "max_step", true, longest}));
  EXPECT_TRUE(notes_.empty());
}

TEST_F(ExperimenterChannelTest, AMisshapenRequestIsRefusedAndNothingIsAsked) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"op":"param"})", "needs a \"name\" string"},
      {R"({"op":"param","name":7})", "needs a \"name\" string"},
      {R"({"op":"param","name":"mixer"})", "COMPONENT.PARAM"},
      {R"({"op":"param","name":".gain"})", "COMPONENT.PARAM"},
      {R"({"op":"param","name":"mixer."})", "COMPONENT.PARAM"},
      {R"({"op":"param","name":"mixer.)" + std::string(300, 'g') + R"("})", "at most 256 bytes"},
      {R"({"op":"param","name":"mixer.gain","value":0.5})", "a string"},
      {R"({"op":"param","name":"mixer.gain","value":null})", "a string"},
      {R"({"op":"param","name":"mixer.gain","value":")" + std::string(4097, '9') + R"("})", "longer than 4 KiB"},
      {R"({"op":"params","name":"mixer.gain"})", "unknown op"},
      {R"(["param","mixer.gain"])", "not a JSON object"},
  };
  for (const auto& [text, why] : cases) {
    const Status s = channel_.OnText(kExperimenter, text);
    EXPECT_EQ(s.code(), Status::Code::kInvalidArgument) << text.substr(0, 80);
    EXPECT_NE(s.message().find(why), std::string::npos) << text.substr(0, 80) << ": " << s.message();
  }
  EXPECT_TRUE(asked_.empty());
}

TEST_F(ExperimenterChannelTest, AViewersRequestIsRefusedAsAViewersNoteIs) {
  const Status note = channel_.OnText(kViewer, R"({"op":"note","text":"hello"})");
  const Status set = channel_.OnText(kViewer, R"({"op":"param","name":"mixer.gain","value":"0.5"})");
  const Status get = channel_.OnText(kViewer, R"({"op":"param","name":"mixer.gain"})");
  EXPECT_EQ(note.code(), Status::Code::kFailedPrecondition);
  EXPECT_EQ(note.message(), "note: the viewer's token may not write notes");
  for (const Status& s : {set, get}) {
    EXPECT_EQ(s.code(), Status::Code::kFailedPrecondition);  // the server closes the page, as for a note
    EXPECT_EQ(s.message(), "param: the viewer's token may not change or read parameters");
  }
  EXPECT_TRUE(asked_.empty());
  EXPECT_TRUE(notes_.empty());
  // A page that went away and a client the channel never saw open count as no experimenter.
  channel_.OnClose(kExperimenter);
  EXPECT_FALSE(channel_.OnText(kExperimenter, R"({"op":"param","name":"mixer.gain"})").ok());
  EXPECT_TRUE(asked_.empty());
}

TEST(ExperimenterChannel, WithoutAParamSinkARequestIsRefused) {
  ExperimenterChannel channel([](const std::string&) {});
  channel.OnOpen(1, Role::kExperimenter);
  EXPECT_FALSE(channel.OnText(1, R"({"op":"param","name":"mixer.gain","value":"0.5"})").ok());
  EXPECT_TRUE(channel.OnText(1, R"({"op":"note","text":"still noted"})").ok());
}

TEST(ExperimenterChannel, APublishingFailureIsToldToThePageWhichStaysOpen) {
  ExperimenterChannel channel([](const std::string&) {}, [](const ParamRequest&) -> StatusOr<std::string> {
    return Status::IOError("DDS write failed");
  });
  channel.OnOpen(1, Role::kExperimenter);
  EXPECT_TRUE(channel.OnText(1, R"({"op":"param","name":"mixer.gain","value":"0.5"})").ok());
}

msg::ParamChange Answer(const std::string& graph, const std::string& op, const std::string& value) {
  msg::ParamChange a;
  a.graph_name(graph);
  a.component_name("mixer");
  a.param_name("gain");
  a.op(op);
  a.value(value);
  a.old_value(op == "applied" ? "0.9" : "");
  a.reason(op == "refused" ? "must be <= 1, got 7" : "");
  a.who("experimenter page");
  a.request_id("r-" + value);
  a.step(42);
  return a;
}

TEST(ParamAnswers, KeepsThisGraphsAnswersNewestLast) {
  ParamAnswers answers("g");
  EXPECT_EQ(answers.Json(), "");
  answers.Add(Answer("g", "set", "0.5"), 1.0);      // a request, not an answer
  answers.Add(Answer("other", "applied", "0.5"), 1.0);  // another graph's
  EXPECT_EQ(answers.Json(), "");
  answers.Add(Answer("g", "applied", "0.25"), 2.0);
  answers.Add(Answer("g", "refused", "7"), 3.0);
  const nlohmann::json j = nlohmann::json::parse(answers.Json());
  EXPECT_EQ(j.at("op"), "params");
  ASSERT_EQ(j.at("items").size(), 2u);
  const nlohmann::json& applied = j.at("items")[0];
  EXPECT_EQ(applied, (nlohmann::json{{"t", 2.0}, {"component", "mixer"}, {"param", "gain"}, {"op", "applied"},
                                     {"value", "0.25"}, {"old_value", "0.9"}, {"reason", ""}, {"who", "experimenter page"},
                                     {"step", 42}, {"request_id", "r-0.25"}}));
  EXPECT_EQ(j.at("items")[1].at("reason"), "must be <= 1, got 7");
  for (int i = 0; i < 30; ++i) answers.Add(Answer("g", "value", std::to_string(i)), 10.0 + i);
  const nlohmann::json last = nlohmann::json::parse(answers.Json()).at("items");
  ASSERT_EQ(last.size(), ParamAnswers::kMaxItems);
  EXPECT_EQ(last.front().at("value"), "10");
  EXPECT_EQ(last.back().at("value"), "29");
}

}  // namespace
}  // namespace dyad::web
