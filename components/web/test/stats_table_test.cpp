// The experimenter's stats table keeps only the graph's own components: a forged or foreign
// dyad/stats sample (fastcdr-serialized, as Fast DDS puts it on the wire) cannot grow it.
#include "stats_table.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <gtest/gtest.h>

#include <vector>

namespace dyad::web {
namespace {

std::vector<uint8_t> Cdr(const std::string& process, const std::string& component, uint64_t steps) {
  msg::ComponentStats s;
  s.process_name(process);
  s.component_name(component);
  s.steps(steps);
  eprosima::fastcdr::FastBuffer buffer;
  eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
  ser.serialize_encapsulation();
  s.serialize(ser);
  return std::vector<uint8_t>(buffer.getBuffer(), buffer.getBuffer() + ser.getSerializedDataLength());
}

TEST(StatsTable, KeepsTheNewestStatsOfTheGraphsOwnComponentsOnly) {
  StatsTable table({{"ui", "web"}, {"worker", "human"}});
  table.Add(Cdr("worker", "human", 5));
  table.Add(Cdr("worker", "human", 7));
  for (int i = 0; i < 1000; ++i) table.Add(Cdr("evil", "forged" + std::to_string(i), 1));  // a peer's names
  table.Add(Cdr("ui", "human", 1));  // a real component under another process
  const std::vector<uint8_t> garbage = {0, 1, 0, 0, 0xff};
  table.Add(garbage);
  EXPECT_EQ(table.size(), 1u);
  const std::string json = table.Json();
  EXPECT_NE(json.find(R"("component":"human")"), std::string::npos) << json;
  EXPECT_NE(json.find(R"("steps":7)"), std::string::npos) << json;
  EXPECT_EQ(json.find("forged"), std::string::npos) << json;
  table.Add(Cdr("ui", "web", 3));
  EXPECT_EQ(table.size(), 2u);
}

}  // namespace
}  // namespace dyad::web
