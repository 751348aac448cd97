// Parsing and validation of the scripted human's intervention events.
#include <gtest/gtest.h>

#include "dyad/human_input/events.hpp"

namespace dyad::human_input {
namespace {

std::string Error(const std::string& yaml, int primitives = 7) {
  auto e = ParseEvents(yaml, primitives);
  return e.ok() ? std::string("OK") : e.status().message();
}

TEST(Events, ParsesASortedList) {
  auto e = ParseEvents("[{start: 10, end: 20, primitive: 2}, {start: 20, end: 35, primitive: 6}]", 7);
  ASSERT_TRUE(e.ok()) << e.status().message();
  ASSERT_EQ(e->size(), 2u);
  EXPECT_EQ((*e)[0].start, 10);
  EXPECT_EQ((*e)[0].end, 20);
  EXPECT_EQ((*e)[0].primitive, 2);
  EXPECT_EQ((*e)[1].primitive, 6);
}

TEST(Events, DefaultEmptyListMeansNoEvents) {
  auto e = ParseEvents("[]", 7);
  ASSERT_TRUE(e.ok());
  EXPECT_TRUE(e->empty());
}

TEST(Events, OverlappingEventsAreAnErrorNamingBoth) {
  EXPECT_EQ(Error("[{start: 100, end: 250, primitive: 1}, {start: 240, end: 300, primitive: 2}]"),
            "events[1]: steps 240..299 overlap events[0] (steps 100..249)");
}

TEST(Events, UnsortedEventsAreAnErrorNamingTheIndex) {
  EXPECT_EQ(Error("[{start: 0, end: 5, primitive: 0}, {start: 50, end: 60, primitive: 1}, {start: 10, end: 20, primitive: 2}]"),
            "events[2]: starts at step 10, before events[1] (step 50): list events in order");
}

TEST(Events, OutOfRangeValuesAreErrorsNamingIndexAndKey) {
  EXPECT_EQ(Error("[{start: 0, end: 5, primitive: 7}]"),
            "events[0].primitive = 7: must be in 0..6 (the data set has 7 primitives)");
  EXPECT_EQ(Error("[{start: 0, end: 5, primitive: -1}]"),
            "events[0].primitive = -1: must be in 0..6 (the data set has 7 primitives)");
  EXPECT_EQ(Error("[{start: 0, end: 5, primitive: 0}, {start: -3, end: 5, primitive: 0}]"),
            "events[1].start = -3: must be >= 0");
  EXPECT_EQ(Error("[{start: 8, end: 8, primitive: 0}]"), "events[0].end = 8: must be > start (8)");
}

TEST(Events, MalformedEntriesAreErrors) {
  EXPECT_EQ(Error("[{start: 0, end: 5}]"), "events[0].primitive: missing");
  EXPECT_EQ(Error("[{start: 0, end: 5, primitive: 1, colour: red}]"),
            "events[0].colour: unknown key (expected start, end, primitive)");
  EXPECT_EQ(Error("[{start: zero, end: 5, primitive: 1}]"), "events[0].start = zero: must be an integer");
  EXPECT_EQ(Error("{start: 0}"), "events: must be a list of {start, end, primitive}");
  EXPECT_EQ(Error("[3]"), "events[0]: must be a map {start, end, primitive}");
}

}  // namespace
}  // namespace dyad::human_input
