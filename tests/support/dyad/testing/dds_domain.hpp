// dyad/testing/dds_domain.hpp: the DDS domains a test process uses for the graphs it runs (test
// code only), so that parallel ctest processes with wall-clock graphs don't hear each other.
// (Stepped graphs are hermetic anyway: their participant ignores other processes.)
//
// A domain is held with an flock on /tmp/dyad-test-domains/D.lock, which the kernel lets go when
// the process ends, however it ends; the shell tests take theirs the same way
// (tests/support/dds_domain.sh). Runs of two tests on one domain would be kept apart by their
// partitions, but not their discovery traffic, nor what a participant reports of the domain's
// other endpoints: a test that counts peers or reads the run's reports would see the other's.
#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

namespace dyad::testing {

// The first of `n` consecutive domains in 1..200 that no other test process holds, held by this
// one until it exits (a second call takes others). Searched from the process id on; if every one
// is held (over 200 tests at once), the process id's, shared.
inline int ClaimDomains(int n) {
  const std::string dir = "/tmp/dyad-test-domains";
  if (mkdir(dir.c_str(), 0777) == 0) chmod(dir.c_str(), 01777);  // any user's tests may take domains
  const int span = 200 - n + 1, start = static_cast<int>(getpid() % span);
  for (int i = 0; i < span; ++i) {
    const int first = 1 + (start + i) % span;
    std::vector<int> held;
    for (int d = first; d < first + n; ++d) {
      const int fd = open((dir + "/" + std::to_string(d) + ".lock").c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0444);
      if (fd < 0) break;
      if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        close(fd);
        break;
      }
      held.push_back(fd);
    }
    if (static_cast<int>(held.size()) == n) return first;  // the descriptors stay open: held
    for (int fd : held) close(fd);
  }
  std::fprintf(stderr, "dyad test: no %d free DDS domain(s) in 1..200 (%s): sharing %d\n", n, dir.c_str(), 1 + start);
  return 1 + start;
}

// This process's domain: claimed on the first call, the same on every later one.
inline int DomainForThisProcess() {
  static const int domain = ClaimDomains(1);
  return domain;
}

}  // namespace dyad::testing
