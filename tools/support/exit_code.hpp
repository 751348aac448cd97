// tools/support/exit_code.hpp: what a `dyad` command's exit code means, one table for every
// command (README.md, "Exit codes", shows the same rows: a test compares them).
//
//   code  ExitCode       meaning
//   0     kOk            done as asked
//   1     kFailure       the input was good and the work failed: a component, a file that could
//                        not be written, a trial or sweep run that did not complete, a refused
//                        request
//   2     kBadInput      bad input: the command line, a file it names, or a request the state
//                        refuses (a trial out of the plan's order, a session another runner
//                        holds); every problem is said, with file:line where there is one, and
//                        nothing is done
//   130   kInterrupted   stopped by Ctrl-C (SIGINT) before the end; what was done is kept
//   143   kTerminated    stopped by SIGTERM before the end; what was done is kept
//
// 130 and 143 are 128 + the signal, as a shell gives them (ForSignal; the runtime's
// ExitCodeForSignal, dyad/interrupt.hpp): `dyad run`, `dyad train`. `dyad sweep` and `dyad study
// run`/`rehearse` exit 130 for SIGTERM too: they stop their children with SIGINT, as a person at
// the keyboard would. `dyad run` takes its code from
// the runtime's ExitCodeOf (dyad/run.hpp), which gives the same rows (a bad param or a missing or
// damaged file the graph names: 2; any other failure: 1). Every command returns an ExitCode;
// Code() gives main its int.
#pragma once

#include <signal.h>

#include <string_view>

namespace dyad::tools {

enum class ExitCode : int {
  kOk = 0,
  kFailure = 1,
  kBadInput = 2,
  kInterrupted = 128 + SIGINT,  // 130
  kTerminated = 128 + SIGTERM,  // 143
};

constexpr int Code(ExitCode code) { return static_cast<int>(code); }

// The code of a command stopped by `signal` (SIGINT or SIGTERM, the two it takes).
constexpr ExitCode ForSignal(int signal) { return signal == SIGTERM ? ExitCode::kTerminated : ExitCode::kInterrupted; }

struct ExitCodeRow {
  ExitCode code;
  std::string_view meaning;  // as README.md's table says it
};

// The table above, in its order.
inline constexpr ExitCodeRow kExitCodes[] = {
    {ExitCode::kOk, "done as asked"},
    {ExitCode::kFailure,
     "the input was good and the work failed: a component, a file that could not be written, a trial or sweep run that "
     "did not complete, a refused request"},
    {ExitCode::kBadInput,
     "bad input: the command line, a file it names, or a request the state refuses (a trial out of the plan's order, a "
     "session another runner holds); every problem is said, with file:line where there is one, and nothing is done"},
    {ExitCode::kInterrupted, "stopped by Ctrl-C (SIGINT) before the end; what was done is kept"},
    {ExitCode::kTerminated, "stopped by SIGTERM before the end; what was done is kept"},
};

}  // namespace dyad::tools
