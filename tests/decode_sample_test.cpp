// DecodeSample (dyad/decode_sample.hpp): serialized samples back to typed messages.
#include <dyad/decode_sample.hpp>

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include <dyad/msg/types.hpp>
#include <dyad/testing/cdr.hpp>

namespace dyad {
namespace {

using testing::Cdr;

TEST(DecodeSample, GivesBackEveryFieldOfASerializedMessage) {
  msg::ComponentStats in;
  in.header().source("runtime");
  in.header().sequence_number(7);
  in.process_name("robot");
  in.component_name("deliberator");
  in.steps(1234);
  in.step_p99_s(0.004);
  const auto cdr = Cdr(in);
  msg::ComponentStats out;
  ASSERT_TRUE(DecodeSample(cdr, &out).ok());
  EXPECT_EQ(out.header().source(), "runtime");
  EXPECT_EQ(out.header().sequence_number(), 7u);
  EXPECT_EQ(out.process_name(), "robot");
  EXPECT_EQ(out.component_name(), "deliberator");
  EXPECT_EQ(out.steps(), 1234u);
  EXPECT_DOUBLE_EQ(out.step_p99_s(), 0.004);
}

TEST(DecodeSample, ShortBytesAreAnInvalidArgumentNamingTheType) {
  msg::ComponentStats in;
  in.component_name("deliberator");
  auto cdr = Cdr(in);
  cdr.resize(6);
  msg::ComponentStats out;
  const Status s = DecodeSample(cdr, &out);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(s.message(), "6 bytes do not decode as dyad::msg::ComponentStats");
}

}  // namespace
}  // namespace dyad
