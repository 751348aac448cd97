// The fixture and helpers of the process-level tests (process_*_test.cpp): real `dyad`
// processes started, signalled, killed and waited for, in a temporary folder of the test's own
// and on a DDS domain of the test process's own (parallel ctest runs never hear each other).
#pragma once

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dyad/testing/child_process.hpp"
#include "dyad/testing/dds_domain.hpp"

namespace dyad::testing {

namespace fs = std::filesystem;
using Child = ChildProcess;

class ProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_test_" + std::to_string(getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A domain of its own per test process, so parallel ctest runs don't hear each other.
    domain_ = DomainForThisProcess();
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  std::vector<std::string> Dyad(std::vector<std::string> args) {
    args.insert(args.begin(), DYAD_EXE);
    return args;
  }
  fs::path dir_;
  int domain_ = 1;
};

// One line of counter_sink's file.
struct Received {
  int64_t value;
  std::string source;
  uint64_t sequence;
  int64_t stamp_ns;
};

inline std::vector<Received> ReadSink(const fs::path& file) {
  std::istringstream lines(ReadFile(file));
  std::vector<Received> out;
  Received r;
  while (lines >> r.value >> r.source >> r.sequence >> r.stamp_ns) out.push_back(r);
  return out;
}

// The steps of `component` in a `dyad run` timing table printed in `out` (0: not found).
inline size_t StepsOf(const std::string& out, const std::string& component) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("[", 0) == 0 && line.find("] ") != std::string::npos) line.erase(0, line.find("] ") + 2);  // "[a] "
    std::istringstream row(line);
    std::string name;
    size_t steps = 0;
    if (row >> name >> steps && name == component) return steps;
  }
  return 0;
}

// A loopback UDP port the kernel says is free now (a fixed one could be a Fast DDS port of a test
// running in parallel on another domain).
inline int FreeUdpPort() {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(a);
  int port = 0;
  if (fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &length) == 0)
    port = ntohs(a.sin_port);
  if (fd >= 0) close(fd);
  return port;
}

// The pid of the `dyad run ... --process P` child whose command line holds `graph`, or 0.
inline pid_t ChildPid(const fs::path& graph, const std::string& process) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline");
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(graph.string()) != std::string::npos && cmdline.find("--process " + process + " ") != std::string::npos)
      return static_cast<pid_t>(std::stoi(name));
  }
  return 0;
}

// ChildPid, waiting up to 5 s for the launcher to start that child; 0 if it did not.
inline pid_t AwaitChildPid(const fs::path& graph, const std::string& process) {
  for (int i = 0; i < 100; ++i) {
    if (const pid_t pid = ChildPid(graph, process)) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

}  // namespace dyad::testing
