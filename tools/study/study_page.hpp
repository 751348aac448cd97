// tools/study/study_page.hpp: `dyad study run --page`: the experimenter's study page, from which
// one participant's session is run instead of from the terminal (docs/study.md).
//
// The page (`/study`, the experimenter's token only; the URL is printed) shows the study, the
// participant, consent, and each planned trial: the condition as the experimenter may see it
// (its label when blind), its status and attempts, and, while one runs, its elapsed time. From
// it the experimenter marks consent, starts the next trial, stops a running one, and repeats a
// trial with a reason. Everything goes through study_session.hpp, as from the terminal: the same
// log, the same files, the same refusals.
//
// WebSocket `/study/ws`, JSON text both ways:
//   page -> server: {"op":"consent"}, {"op":"start","trial":k,"reason":"..."} (reason: for a
//     trial with an earlier attempt), {"op":"stop"}
//   server -> page: {"op":"state", "study", "participant", "blind", "consent_required",
//     "consent", "duration_s", "trials":[{"number","shown","file","status","attempts"}] (status:
//     to do, running, complete, stopped, failed, interrupted, incomplete, or "no subject: repeat?"
//     as soon as a trial ends whole with nobody taking part: study_session.hpp's NoSubject),
//     "running":{"trial","attempt","elapsed_s"}|null, "done":bool}, after each change and once a
//     second while a trial runs; {"op":"error","message"} for a refused request (the page stays).
// A trial starts only in the plan's order (the next one not complete), or again with a reason.
//
// Threads: requests come on the web server's handler thread; an attempt runs on a thread of its
// own; `stop` and SIGINT stop it (one SIGINT to the graph). SIGINT or SIGTERM between trials ends
// the page session.
#pragma once

#include <string>

#include "exit_code.hpp"
#include "study_file.hpp"

namespace dyad::study {

struct PageOptions {
  std::string dyad;                  // the dyad executable
  std::string address = "127.0.0.1";
  int port = 8770;                   // 0: any free port
  std::string port_file;             // written with the bound port (tests, scripts)
  // The subject's page between trials (subject_lobby.hpp) binds the graph's web component's
  // port, which each trial's graph is then given: -1 its params.port (8765 by default), 0 any free one.
  int subject_port = -1;
};

// Serves the page until SIGINT/SIGTERM between trials, or until every trial is complete. Returns
// the command's exit code: kOk once every trial of the participant is complete; kFailure while
// trials remain (as the terminal's session) or when the page or the subject's page between
// trials cannot open (said on stderr).
tools::ExitCode RunStudyPage(const Study& study, const std::string& participant, const PageOptions& options);

}  // namespace dyad::study
