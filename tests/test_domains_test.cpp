// The DDS domains test processes hold (dyad/testing/dds_domain.hpp): one held is not handed out
// again while its holder lives, in this process or another, and is free again once it exits.
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

#include <gtest/gtest.h>

#include "dyad/testing/dds_domain.hpp"

namespace dyad::testing {
namespace {

// What ClaimDomains(n) gives a child process (forked: it inherits the parent's descriptors, but
// a lock belongs to its own opening of the file), while the parent holds its own.
int ClaimInChild(int n) {
  int fds[2];
  if (pipe(fds) != 0) return -1;
  const pid_t pid = fork();
  if (pid == 0) {
    const int d = ClaimDomains(n);
    (void)!write(fds[1], &d, sizeof d);
    _exit(0);
  }
  close(fds[1]);
  int d = -1;
  if (read(fds[0], &d, sizeof d) != static_cast<ssize_t>(sizeof d)) d = -1;
  close(fds[0]);
  waitpid(pid, nullptr, 0);
  return d;
}

bool Lockable(int domain) {
  const int fd = open(("/tmp/dyad-test-domains/" + std::to_string(domain) + ".lock").c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool free = flock(fd, LOCK_EX | LOCK_NB) == 0;
  close(fd);
  return free;
}

TEST(TestDomains, AHeldDomainIsNotHandedOutAgainUntilItsHolderEnds) {
  const int mine = DomainForThisProcess();
  EXPECT_EQ(DomainForThisProcess(), mine) << "the same on every call";
  const int range = ClaimDomains(3);
  EXPECT_TRUE(mine < range || mine > range + 2) << mine << " inside " << range << "-" << range + 2;
  const int child = ClaimInChild(1);
  ASSERT_GE(child, 1);
  EXPECT_NE(child, mine);
  EXPECT_TRUE(child < range || child > range + 2) << child << " inside " << range << "-" << range + 2;
  // Read by a lock of its own on the files: the child's domain is free again once it exited,
  // this process's is not.
  EXPECT_TRUE(Lockable(child)) << "a domain is let go when its holder exits";
  EXPECT_FALSE(Lockable(mine)) << "a domain is held while its holder lives";
}

}  // namespace
}  // namespace dyad::testing
