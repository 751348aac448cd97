// The dyad command line: one executable, one subcommand per job. Each command group lives in
// its own library and adds its subcommands here.
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <fastdds/dds/log/Log.hpp>

#include "analyze_commands.hpp"
#include "bag_commands.hpp"
#include "exit_code.hpp"
#include "guest_commands.hpp"
#include "introspection_commands.hpp"
#include "observer_commands.hpp"
#include "pvrnn_commands.hpp"
#include "runtime_commands.hpp"
#include "security_commands.hpp"
#include "study_commands.hpp"
#include "sweep_commands.hpp"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define DYAD_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define DYAD_SANITIZED 1
#endif

namespace {

// Fast DDS 2.9's DomainParticipantFactory destructor sleeps 100 ms at exit, whatever is left to
// do (~DomainParticipantFactory: sleep_for(100ms)): 40% of a 200-step stepped run of the demo,
// and of every command's time. Every participant and file of ours is closed by now (each command
// owns them in its scope), so: flush what is pending, Fast DDS's log included, and leave without
// static destructors. Sanitizer builds exit the normal way (LeakSanitizer checks at exit).
int QuickExit(int code) {
#ifdef DYAD_SANITIZED
  return code;
#else
  eprosima::fastdds::dds::Log::Flush();
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  // A closed output (`dyad echo T | head`) makes writes fail instead of killing the process, so
  // every command ends cleanly (DDS participants deleted, files closed).
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"dyad: human-robot interaction experiments as graphs of components over DDS"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show every subcommand's help");
  int exit_code = dyad::tools::Code(dyad::tools::ExitCode::kOk);  // each command sets its own (exit_code.hpp)
  dyad::cli::AddRuntimeCommands(app, exit_code);
  dyad::cli::AddIntrospectionCommands(app, exit_code);
  dyad::cli::AddSecurityCommands(app, exit_code);
  dyad::cli::AddBagCommands(app, exit_code);
  dyad::cli::AddGuestCommands(app, exit_code);  // after bag: it adds `bag play`
  dyad::cli::AddPvrnnCommands(app, exit_code);
  dyad::cli::AddObserverCommands(app, exit_code);
  dyad::cli::AddAnalyzeCommands(app, exit_code);
  dyad::cli::AddSweepCommands(app, exit_code);
  dyad::cli::AddStudyCommands(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    using enum dyad::tools::ExitCode;
    return dyad::tools::Code(code == 0 ? kOk : kBadInput);  // --help is ok; a usage error is bad input
  }
  return QuickExit(exit_code);
}
