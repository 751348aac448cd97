// The launcher's spawner (hosts/spawner.hpp): a child gets stdout and stderr on the relay and no
// other descriptor of the launcher (its DDS sockets, other children's pipes), in its own process
// group. The "dyad binary" here is /bin/sh, which lists what it was given.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <sstream>
#include <string>

#include "hosts/output_relay.hpp"
#include "hosts/spawner.hpp"

namespace dyad {
namespace {

int WaitFor(pid_t pid) {
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, 0), pid);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

TEST(Spawner, AChildInheritsNoDescriptorButItsOutputAndRunsInItsOwnGroup) {
  // A descriptor of the launcher's that is not close-on-exec (as a socket of a library may be).
  // (Numbered apart from the 3 `ls` itself opens.)
  const int first = open("/dev/null", O_RDONLY);
  ASSERT_GE(first, 3);
  const int open_fd = dup2(first, 57);
  close(first);
  ASSERT_EQ(open_fd, 57);
  std::ostringstream out, err;
  pid_t pid = 0;
  {
    OutputRelay relay(out, err);
    Spawner spawner("/bin/sh", &relay, "here");
    // argv[0] "sh"; the shell lists its open descriptors (its own for reading the directory aside).
    auto started = spawner.Start(
        "probe", {"sh", "-c", "ls /proc/self/fd | tr '\\n' ' '; echo; echo pgid=$(cut -d' ' -f5 /proc/$$/stat) pid=$$"}, 0, "");
    ASSERT_TRUE(started.ok()) << started.status().message();
    pid = started.value();
    EXPECT_EQ(WaitFor(pid), 0);
  }  // the relay has read the pipes to the end
  close(open_fd);
  const std::string text = out.str();
  // 0, 1, 2 and the descriptor `ls` opens for /proc/self/fd: nothing of ours.
  EXPECT_EQ(text.find(" 57 "), std::string::npos) << text;
  std::istringstream fds(text.substr(text.find(']') + 1));
  int n = 0, count = 0;
  while (fds >> n) ++count;
  EXPECT_LE(count, 4) << text;
  EXPECT_NE(text.find("pgid=" + std::to_string(pid) + " pid=" + std::to_string(pid)), std::string::npos) << text;
}

TEST(Spawner, AnExecutableThatCannotRunIsAnExitOf127) {
  std::ostringstream out, err;
  OutputRelay relay(out, err);
  Spawner spawner("/nonexistent/dyad", &relay, "here");
  auto started = spawner.Start("ghost", {"dyad", "run"}, 0, "");
  ASSERT_TRUE(started.ok()) << started.status().message();  // fork succeeded; exec fails in the child
  EXPECT_EQ(WaitFor(started.value()), 127);
}

}  // namespace
}  // namespace dyad
