// The server's small helpers: token comparison and the URLs it prints.
#include "web_server.hpp"

#include <gtest/gtest.h>

namespace dyad::web {
namespace {

TEST(TokenMatches, OnlyTheExactTokenAndNeverAnEmptyOne) {
  EXPECT_TRUE(TokenMatches("0123abcd", "0123abcd"));
  EXPECT_FALSE(TokenMatches("0123abce", "0123abcd"));
  EXPECT_FALSE(TokenMatches("0123abc", "0123abcd"));    // a prefix
  EXPECT_FALSE(TokenMatches("0123abcdX", "0123abcd"));  // longer
  EXPECT_FALSE(TokenMatches("", ""));                   // no token configured: nothing matches
  EXPECT_FALSE(TokenMatches(std::string_view("0123\0bcd", 8), "0123abcd"));
}

// Bound to 0.0.0.0 the server used to print http://0.0.0.0:8765/..., which opens nothing.
TEST(UrlHosts, AWildcardBecomesTheMachinesAddresses) {
  EXPECT_EQ(UrlHosts("127.0.0.1"), std::vector<std::string>{"127.0.0.1"});
  EXPECT_EQ(UrlHosts("::1"), std::vector<std::string>{"[::1]"});
  const auto hosts = UrlHosts("0.0.0.0");
  ASSERT_FALSE(hosts.empty());
  for (const auto& h : hosts) {
    EXPECT_NE(h, "0.0.0.0");
    EXPECT_EQ(h.find(':'), std::string::npos) << h;  // IPv4 addresses
  }
}

}  // namespace
}  // namespace dyad::web
