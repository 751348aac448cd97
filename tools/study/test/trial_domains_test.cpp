// The trials' DDS domains of dyad study serve (trial_domains.hpp): the range parsed and resolved,
// each error naming what to change, and the pool's take and give back.
#include "trial_domains.hpp"

#include <gtest/gtest.h>

namespace dyad::study {
namespace {

TEST(TrialDomains, ARangeIsTwoDomainIdsInOrderWithinDds) {
  const auto r = ParseDomainRange("40-55");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->first, 40);
  EXPECT_EQ(r->last, 55);
  EXPECT_EQ(r->size(), 16);
  EXPECT_TRUE(ParseDomainRange("0-232").ok());
  EXPECT_TRUE(ParseDomainRange("7-7").ok());
  for (const char* bad : {"", "40", "40-", "-40", "55-40", "0-233", "a-b", "40-55x", " 40-55", "40--55", "-1-5"}) {
    const auto b = ParseDomainRange(bad);
    ASSERT_FALSE(b.ok()) << "'" << bad << "' taken";
    EXPECT_NE(b.status().message().find("want FIRST-LAST, two DDS domain ids in 0..232"), std::string::npos)
        << b.status().message();
  }
}

TEST(TrialDomains, TheRangeHoldsOneDomainPerLiveSessionAndItsErrorSaysWhatToChange) {
  const auto from_graph = TrialDomainRange(std::nullopt, "online.domains", 5, 16);
  ASSERT_TRUE(from_graph.ok()) << from_graph.status().ToString();
  EXPECT_EQ(from_graph->first, 5);
  EXPECT_EQ(from_graph->last, 20) << "the graph's domain_id and the max_sessions - 1 after it";
  const auto past = TrialDomainRange(std::nullopt, "online.domains", 220, 16);
  ASSERT_FALSE(past.ok());
  EXPECT_NE(past.status().message().find("need domains 220-235"), std::string::npos) << past.status().message();
  EXPECT_NE(past.status().message().find("set online.domains (or --domains)"), std::string::npos) << past.status().message();
  const auto given = TrialDomainRange(DomainRange{40, 55}, "--domains", 0, 16);
  ASSERT_TRUE(given.ok());
  EXPECT_EQ(given->first, 40);
  const auto small = TrialDomainRange(DomainRange{40, 49}, "s.yaml: online.domains", 0, 16);
  ASSERT_FALSE(small.ok());
  EXPECT_EQ(small.status().message(),
            "s.yaml: online.domains 40-49 holds 10 domains for max_sessions 16 (each live session's trial runs on a domain of "
            "its own): widen it, or lower max_sessions (--max-sessions, online.max_sessions)");
}

// In order at first, then the domain given back longest ago: one given back just now (its graph's
// launcher gone, a process of it perhaps still ending) is the last to be taken again.
TEST(TrialDomains, EachTakeIsTheDomainFreeLongestUntilNoneIsLeft) {
  TrialDomains pool(DomainRange{40, 42});
  EXPECT_EQ(pool.Take(), 40);
  EXPECT_EQ(pool.Take(), 41);
  pool.Give(40);
  EXPECT_EQ(pool.Take(), 42) << "42 was free longer than 40, given back just now";
  EXPECT_EQ(pool.Take(), 40);
  EXPECT_EQ(pool.Take(), std::nullopt) << "three domains, three trials";
  pool.Give(41);
  pool.Give(41);  // free already: nothing changes
  pool.Give(99);  // not of the range: nothing changes
  EXPECT_EQ(pool.Take(), 41) << "a domain given back is taken again";
  EXPECT_EQ(pool.Take(), std::nullopt);
  TrialDomains none(DomainRange{});
  EXPECT_EQ(none.range().size(), 0);
  EXPECT_EQ(none.Take(), std::nullopt);
}

}  // namespace
}  // namespace dyad::study
