// What the experimenter's page is told of the run: restarts, failures, endpoint health.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "run_events.hpp"

namespace dyad::web {
namespace {

msg::ProcessState State(const std::string& process, const std::string& state, uint64_t restarts) {
  msg::ProcessState s;
  s.process_name(process);
  s.host("mind-pc");
  s.state(state);
  s.restarts(restarts);
  return s;
}

std::vector<std::string> Texts(const RunEvents& events) {
  std::vector<std::string> out;
  const std::string j = events.Json();
  if (j.empty()) return out;
  const nlohmann::json parsed = nlohmann::json::parse(j);  // (not in the range-for: its temporary would die first)
  for (const auto& item : parsed.at("items")) out.push_back(item.at("text").get<std::string>());
  return out;
}

TEST(RunEvents, ARestartIsSaidOnceWhenTheCountGrowsAndAFailureOnce) {
  RunEvents events;
  EXPECT_EQ(events.Json(), "");
  events.Add(State("mind", "running", 0), 1.0);
  events.Add(State("mind", "running", 0), 2.0);
  EXPECT_TRUE(Texts(events).empty());
  events.Add(State("mind", "waiting", 1), 3.0);
  events.Add(State("mind", "running", 1), 4.0);  // the same restart, announced again
  events.Add(State("mind", "failed", 1), 5.0);
  events.Add(State("mind", "failed", 1), 6.0);
  const auto texts = Texts(events);
  ASSERT_EQ(texts.size(), 2u);
  EXPECT_EQ(texts[0].rfind("process 'mind' on host 'mind-pc' restarted (restart 1): its components started afresh", 0), 0u)
      << texts[0];
  EXPECT_EQ(texts[1], "process 'mind' on host 'mind-pc' failed for good");
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(events.Json()).at("items")[0].at("t").get<double>(), 3.0);
}

TEST(RunEvents, HealthActionsAreSaidButAPostponementIsNot) {
  RunEvents events;
  msg::HealthEvent e;
  e.process_name("rec");
  e.endpoint("reader");
  e.topic("robot/state");
  e.starved_s(1.25);
  e.renewals(1);
  for (const char* action : {"postponed", "renewed", "healed"}) {
    e.action(action);
    events.Add(e, 1.0);
  }
  e.endpoint("participant");
  e.topic("");
  e.action("cannot heal");
  e.renewals(5);
  events.Add(e, 2.0);
  const auto texts = Texts(events);
  ASSERT_EQ(texts.size(), 3u);
  EXPECT_EQ(texts[0], "process 'rec' renewed its reader of 'robot/state' (it heard nothing for 1.2 s; renewal 1)");
  EXPECT_EQ(texts[1], "process 'rec': its reader of 'robot/state' is matched again");
  EXPECT_EQ(texts[2], "process 'rec' cannot heal its DDS participant after 5 renewals: it ends as failed");
}

TEST(RunEvents, KeepsTheNewest) {
  RunEvents events;
  for (uint64_t r = 1; r <= RunEvents::kMaxItems + 5; ++r) events.Add(State("mind", "running", r), static_cast<double>(r));
  const auto items = nlohmann::json::parse(events.Json()).at("items");
  ASSERT_EQ(items.size(), RunEvents::kMaxItems);
  EXPECT_DOUBLE_EQ(items[0].at("t").get<double>(), 6.0);
}

}  // namespace
}  // namespace dyad::web
