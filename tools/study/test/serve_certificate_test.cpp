// The certificate of `dyad study serve --tls-certificate` (serve_certificate.hpp), without a
// server: made with the openssl command (a key and a certificate of one day, or of a day ago),
// read at chosen instants. serve_tls_test.sh covers the refusals through the command and the
// certificate in browsers.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "serve_certificate.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;

class ServeCertificateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_serve_certificate_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  // NAME.key and NAME.crt, self-signed for `alt` (a subjectAltName), valid one day from now.
  void Make(const std::string& name, const std::string& alt) {
    const std::string cmd = "openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:P-256 -nodes -days 1 -subj /CN=" + name +
                            " -addext subjectAltName=" + alt + " -keyout " + Path(name + ".key") + " -out " +
                            Path(name + ".crt") + " 2> /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  // A 0600 PEM of `parts` (files of dir_) one after the other.
  std::string Pem(const std::string& name, std::initializer_list<std::string> parts) {
    std::ofstream out(Path(name));
    for (const std::string& p : parts) out << std::ifstream(Path(p)).rdbuf();
    out.close();
    chmod(Path(name).c_str(), 0600);
    return Path(name);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string Why(const StatusOr<ServeCertificate>& c) { return c.ok() ? "accepted" : std::string(c.status().message()); }
  fs::path dir_;
  const std::time_t now_ = std::time(nullptr);
};

TEST_F(ServeCertificateTest, AKeyThenItsCertificateGivesTheNamesAHostIsCheckedAgainst) {
  Make("a", "DNS:study.test,DNS:*.lab.test,IP:127.0.0.1,IP:::1");
  auto c = ReadServeCertificate(Pem("a.pem", {"a.key", "a.crt"}), now_);
  ASSERT_TRUE(c.ok()) << Why(c);
  EXPECT_EQ(c->names(), (std::vector<std::string>{"DNS:study.test", "DNS:*.lab.test", "IP:127.0.0.1", "IP:0:0:0:0:0:0:0:1"}));
  EXPECT_NE(c->not_after().find(" UTC"), std::string::npos) << c->not_after();
  for (const char* host : {"study.test", "STUDY.test", "rig.lab.test", "127.0.0.1", "[::1]", "::1"})
    EXPECT_TRUE(c->Names(host)) << host;
  for (const char* host : {"other.test", "a.rig.lab.test", "lab.test", "127.0.0.2", "192.0.2.2", "localhost"})
    EXPECT_FALSE(c->Names(host)) << host;
}

TEST_F(ServeCertificateTest, WhatABrowserWouldRefuseIsRefusedNamingTheFlag) {
  Make("a", "DNS:study.test");
  Make("b", "DNS:study.test");
  const std::string good = Pem("a.pem", {"a.key", "a.crt"});
  auto starts = [&](const std::string& path, const std::string& what) { return "--tls-certificate '" + path + "': " + what; };
  const std::string cert_only = Pem("crt.pem", {"a.crt"}), key_only = Pem("key.pem", {"a.key"});
  const std::string mixed = Pem("mixed.pem", {"a.key", "b.crt"}), missing = Path("missing.pem");
  EXPECT_EQ(Why(ReadServeCertificate(cert_only, now_)).rfind(starts(cert_only, "no private key in it"), 0), 0u);
  EXPECT_EQ(Why(ReadServeCertificate(key_only, now_)).rfind(starts(key_only, "no certificate in it"), 0), 0u);
  EXPECT_EQ(Why(ReadServeCertificate(mixed, now_)), starts(mixed, "its private key is not its certificate's"));
  EXPECT_EQ(Why(ReadServeCertificate(missing, now_)).rfind(starts(missing, "No such file or directory"), 0), 0u);
  EXPECT_EQ(Why(ReadServeCertificate(dir_.string(), now_)).rfind(starts(dir_.string(), "not a regular file"), 0), 0u);
  EXPECT_EQ(Why(ReadServeCertificate(good, now_ + 3 * 86400)).rfind(starts(good, "expired "), 0), 0u);
  EXPECT_NE(Why(ReadServeCertificate(good, now_ + 3 * 86400)).find("--renew web"), std::string::npos);
  EXPECT_EQ(Why(ReadServeCertificate(good, now_ - 86400)).rfind(starts(good, "not valid before "), 0), 0u);
  chmod(good.c_str(), 0640);
  EXPECT_EQ(Why(ReadServeCertificate(good, now_)), starts(good, "holds the private key and is readable by others: chmod 600 it"));
}

}  // namespace
}  // namespace dyad::study
