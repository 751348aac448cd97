// `dyad param`'s "who": $USER, else the account name from the password database (a service or a
// container often runs without $USER; the change then read "?@host").
#include <gtest/gtest.h>
#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <optional>
#include <string>

#include "guest_commands.hpp"

namespace dyad::cli {
namespace {

class ParamWho : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const char* u = std::getenv("USER")) saved_ = u;
    char h[256] = {0};
    gethostname(h, sizeof(h) - 1);
    host_ = h;
  }
  void TearDown() override {
    if (saved_) setenv("USER", saved_->c_str(), 1);
    else unsetenv("USER");
  }
  std::optional<std::string> saved_;
  std::string host_;
};

TEST_F(ParamWho, UserFromTheEnvironment) {
  setenv("USER", "alice", 1);
  EXPECT_EQ(ParamRequester(), "dyad param (alice@" + host_ + ")");
}

TEST_F(ParamWho, AccountNameWhenUserIsUnsetOrEmpty) {
  const passwd* pw = getpwuid(getuid());
  if (pw == nullptr) GTEST_SKIP() << "uid " << getuid() << " has no entry in the password database";
  const std::string expected = "dyad param (" + std::string(pw->pw_name) + "@" + host_ + ")";
  unsetenv("USER");
  EXPECT_EQ(ParamRequester(), expected);
  setenv("USER", "", 1);
  EXPECT_EQ(ParamRequester(), expected);
}

}  // namespace
}  // namespace dyad::cli
