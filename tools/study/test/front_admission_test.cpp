// Who a request to `dyad study serve` is (front_admission.hpp), without a server: a participant's
// token is admitted whatever its address did, unknown tokens are limited per address (IPv6 by
// its /64), and the limit's memory is bounded.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>
#include <vector>

#include "front_admission.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Clock = FrontAdmission::Clock;

class FrontAdmissionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dyad_admission_" + std::to_string(getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    study_.file = (dir_ / "s.yaml").string();
    study_.data = (dir_ / "data").string();
    study_.participants = {"P01"};
    study_.token_file_webs = {"web"};
    fs::create_directories(dir_ / "data" / "P01");
    const fs::path tokens = dir_ / "data" / "P01" / "web-tokens";
    std::ofstream(tokens) << "subject " << kToken << "\n";
    fs::permissions(tokens, fs::perms::owner_read | fs::perms::owner_write);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  static int Code(const std::variant<web::Admission, web::Refusal>& v) {
    return std::holds_alternative<web::Admission>(v) ? 200 : std::get<web::Refusal>(v).status;
  }
  static constexpr const char* kToken = "0123456789abcdef0123456789abcdef";
  fs::path dir_;
  Study study_;
};

TEST_F(FrontAdmissionTest, AKnownTokenIsAdmittedFromAnAddressThatGuessed) {
  std::vector<std::string> problems;
  FrontAdmission a(study_, &problems);
  ASSERT_TRUE(problems.empty()) << problems.front();
  const auto now = Clock::now();
  for (int i = 0; i <= FrontAdmission::kUnknownPerMinute; ++i) EXPECT_EQ(Code(a.Admit("guess", "10.0.0.1", now)), 404) << i;
  EXPECT_EQ(Code(a.Admit("guess", "10.0.0.1", now)), 429);
  const auto known = a.Admit(kToken, "10.0.0.1", now);
  ASSERT_EQ(Code(known), 200) << "behind a proxy every participant has the guesser's address";
  EXPECT_EQ(std::get<web::Admission>(known).who, "P01");
  EXPECT_EQ(Code(a.Admit("guess", "10.0.0.2", now)), 404) << "another address";
  EXPECT_EQ(Code(a.Admit("guess", "10.0.0.1", now + std::chrono::seconds(61))), 404) << "the minute is over";
}

TEST_F(FrontAdmissionTest, IPv6AddressesCountByTheirSlash64) {
  EXPECT_EQ(FrontAdmission::AddressKey("2001:db8:0:7:1:2:3:4"), "2001:db8:0:7::/64");
  EXPECT_EQ(FrontAdmission::AddressKey("::ffff:10.0.0.1"), "10.0.0.1");
  EXPECT_EQ(FrontAdmission::AddressKey("10.0.0.1"), "10.0.0.1");
  FrontAdmission a(study_, nullptr);
  const auto now = Clock::now();
  for (int i = 0; i <= FrontAdmission::kUnknownPerMinute; ++i)  // a new address of one /64 each time
    EXPECT_EQ(Code(a.Admit("guess", "2001:db8::" + std::to_string(i + 1), now)), 404) << i;
  EXPECT_EQ(Code(a.Admit("guess", "2001:db8::ff", now)), 429) << "the same /64";
  EXPECT_EQ(Code(a.Admit("guess", "2001:db8:0:1::1", now)), 404) << "another /64";
}

TEST_F(FrontAdmissionTest, TheAddressesKeptAreBounded) {
  FrontAdmission a(study_, nullptr);
  const auto now = Clock::now();
  for (size_t i = 0; i < FrontAdmission::kMaxAddresses; ++i) {
    const std::string address =
        "10." + std::to_string(i / 65536) + "." + std::to_string(i / 256 % 256) + "." + std::to_string(i % 256);
    ASSERT_EQ(Code(a.Admit("guess", address, now)), 404) << address;
  }
  EXPECT_EQ(Code(a.Admit("guess", "192.168.0.1", now)), 429) << "full: an unknown token from a new address waits";
  EXPECT_EQ(Code(a.Admit(kToken, "192.168.0.1", now)), 200) << "a known one never does";
  EXPECT_EQ(Code(a.Admit("guess", "192.168.0.1", now + std::chrono::seconds(61))), 404) << "the old windows swept";
}

}  // namespace
}  // namespace dyad::study
