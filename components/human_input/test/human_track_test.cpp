// Reading a human track from CSV (dyad bag export --csv of a HumanInput topic).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dyad/human_input/human_track.hpp"

namespace dyad::human_input {
namespace {

std::string Write(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("dyad_human_track_" + name);
  std::ofstream(p) << text;
  return p.string();
}

TEST(HumanTrack, ReadsTheBagExportLayoutByHeaderName) {
  const std::string p = Write("ok.csv",
                              "log_time,publish_time,sequence,header.source,header.sequence_number,header.stamp_ns,x,y,engaged\n"
                              "1,1,1,human,1,0,1.5,-2,false\n"
                              "2,2,2,\"hu,man\",2,100,3.25,4e1,true\n");
  auto rows = LoadHumanTrack(p);
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_DOUBLE_EQ((*rows)[0].x, 1.5);
  EXPECT_DOUBLE_EQ((*rows)[0].y, -2);
  EXPECT_FALSE((*rows)[0].engaged);
  EXPECT_DOUBLE_EQ((*rows)[1].x, 3.25);
  EXPECT_DOUBLE_EQ((*rows)[1].y, 40);
  EXPECT_TRUE((*rows)[1].engaged);
}

TEST(HumanTrack, ColumnOrderDoesNotMatterAndOneZeroAreFlags) {
  auto rows = LoadHumanTrack(Write("order.csv", "engaged,y,x\n1,2,3\n0,5,6\n"));
  ASSERT_TRUE(rows.ok()) << rows.status().message();
  EXPECT_TRUE((*rows)[0].engaged);
  EXPECT_DOUBLE_EQ((*rows)[0].x, 3);
  EXPECT_DOUBLE_EQ((*rows)[1].y, 5);
}

TEST(HumanTrack, ErrorsNameFileLineAndColumn) {
  const std::string p1 = Write("nocol.csv", "x,y\n1,2\n");
  EXPECT_EQ(LoadHumanTrack(p1).status().message(), p1 + ": no column \"engaged\" in the header");
  const std::string p2 = Write("bad.csv", "x,y,engaged\n1,2,true\n1,abc,true\n");
  EXPECT_EQ(LoadHumanTrack(p2).status().message(), p2 + ":3: y: not a finite number: \"abc\"");
  const std::string p3 = Write("flag.csv", "x,y,engaged\n1,2,maybe\n");
  EXPECT_EQ(LoadHumanTrack(p3).status().message(), p3 + ":2: engaged: must be true/false or 1/0, got \"maybe\"");
  const std::string p4 = Write("empty.csv", "x,y,engaged\n");
  EXPECT_EQ(LoadHumanTrack(p4).status().message(), p4 + ": no data rows after the header");
  EXPECT_FALSE(LoadHumanTrack("/nonexistent/h.csv").ok());
}

}  // namespace
}  // namespace dyad::human_input
