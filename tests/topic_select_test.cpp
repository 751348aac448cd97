// SelectTopics (dyad/topic_select.hpp): the `topics` params of recorder, replay and web.
#include <dyad/topic_select.hpp>

#include <gtest/gtest.h>

namespace dyad {
namespace {

TEST(SelectTopics, EmptyChoosesAllButTheExcluded) {
  auto r = SelectTopics({}, {"a", "b", "dyad/stats"}, "params.topics", {"dyad/stats"});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(*r, (std::vector<std::string>{"a", "b"}));
}

TEST(SelectTopics, NamesAndRegexesMatchWholeNamesInGraphOrder) {
  auto r = SelectTopics({"robot/.*", "human/input"}, {"human/input", "robot/command", "robot/state", "xrobot/y"}, "p");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(*r, (std::vector<std::string>{"human/input", "robot/command", "robot/state"}));
}

TEST(SelectTopics, APatternMatchingNothingNamesTheParamEntry) {
  auto r = SelectTopics({"a", "nope"}, {"a", "b"}, "params.topics");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "params.topics[1] = 'nope': matches no topic (topics: a, b)");
}

TEST(SelectTopics, AnInvalidRegexNamesTheParamEntry) {
  auto r = SelectTopics({"a[b"}, {"a"}, "params.topics");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("params.topics[0] = 'a[b': neither a topic nor a valid regular expression"), std::string::npos)
      << r.status().message();
}

TEST(SelectTopics, ANamedPatternChoosesAnExcludedTopicOnceEvenIfMatchedTwice) {
  auto r = SelectTopics({"dyad/stats", "dyad/.*"}, {"a", "dyad/stats"}, "params.topics", {"dyad/stats"});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(*r, (std::vector<std::string>{"dyad/stats"}));
}

}  // namespace
}  // namespace dyad
