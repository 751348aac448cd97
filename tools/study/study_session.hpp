// tools/study/study_session.hpp: one participant's session of a study: consent, the attempts at
// each planned trial, and the log that keeps them (docs/study.md, "Running a session").
//
// The session log, DATA/PARTICIPANT/session.log, one JSON object per line, only ever appended
// (created 0600):
//   {"time":"2026-11-26T20:31:05Z","event":"consent","how":"..."}
//   {"time":...,"event":"start","trial":3,"attempt":2,"file":"/abs/03-B.try2.mcap","reason":"..."}
//   {"time":...,"event":"start",...,"start_anyway":"without the subject's page"}  the experimenter's choice
//   {"time":...,"event":"end","trial":3,"attempt":2,"outcome":"complete","seconds":120.0,"exit":0,
//    "ended":"exited with code 0"}   exit: the shell's number; ended: how the graph ended, in words
//    (child_process.hpp's ExitStatus: "killed by signal 9 (Killed)", "never started: ...")
//   {"time":...,"event":"end",...,"outcome":"incomplete","incomplete":"no subject: ..."}  nobody took part
//   {"time":...,"event":"note","text":"...","trial":3}       the experimenter's (dyad study note, the page);
//                                                             trial: the one under way (none between trials)
//   {"time":...,"event":"withdrawn","how":"...","data":"kept"|"deleted"}   consent withdrawn
//   {"time":...,"event":"excluded","reason":"..."} / {"time":...,"event":"included","reason":"..."}
// Consent and withdrawal: the later line holds. Exclusion and inclusion: the later line holds.
// Each line is on disk (fdatasync, and the folder's entry when the log is new) before the call
// that wrote it returns: a trial never starts on a consent a power cut could lose.
// outcome: one word of AttemptOutcome (attempt_outcome.hpp says what each means); with
// incomplete, "incomplete" says why (NoSubject, or the caller's incomplete_reason). A start without its end: the session itself
// ended mid-trial ("interrupted", AttemptOutcome::kUnended).
//
// Contract:
//   - AttemptFile: attempt 1 of a trial records into Trial::file (DATA/P01/03-B.mcap), attempt k
//     into DATA/P01/03-B.try<k>.mcap. A repetition never replaces the earlier attempt.
//   - ReadSession never fails: lines it cannot read are listed in `problems` (file:line) and
//     skipped; a missing log is a session that has not started.
//   - RunAttempt refuses (nothing started, nothing logged) a trial when consent is required and
//     not marked, or when the attempt's file exists. Otherwise it logs the start, runs
//     `dyad run` on the graph with the condition's overrides, the recorder's file and the
//     metadata below, and logs the end. While it runs, SIGINT (Ctrl-C) or SIGTERM stops the
//     trial: the graph gets one SIGINT (it is in a process group of its own, with SIGINT as its
//     parent-death signal: a runner that dies, even by SIGKILL, stops it too) and finishes its
//     recording; a second one is forwarded too (dyad then exits at once), and a graph still
//     there 10 s after it is killed with its process group. A stop through AttemptRequest::stop
//     (set once) becomes the second one by itself after stop_grace (10 s): a graph that hangs
//     while ending is killed even when nobody can press Ctrl-C again (`dyad study serve`). Attempt::interrupted says a signal
//     came, so a caller running several trials stops there.
//   - Recording metadata ("dyad.run" in the MCAP file): study, participant, condition (its label
//     when the study is blind), trial, attempt, rehearsal (true|false), dyad_version (the
//     runner's), graph_hash (FNV-1a of the top graph file's text and the run's overrides, hex;
//     not of the files it extends, its models or plugins). Blinding covers file names, this
//     metadata and the runner's output, not the recording's contents: its "dyad.graph" record
//     holds the graph as run, the condition's values included.
//   - WhyNotStart: the plan's order, the same for every front end: a trial never run starts only
//     when it is the first one not complete; one run before starts again only with a reason.
//   - SessionLock: one runner per participant at a time (flock on DATA/P/session.lock).
//   - Withdrawal: nothing records for a participant who withdrew consent (RunAttempt refuses, and
//     so do both front ends) until a new consent is marked explicitly, and the analysis leaves
//     them out. WithdrawConsent with delete_data removes every file of the participant's folder
//     but the lock and then replaces the log with one line saying so (the one exception to "only
//     appended": notes and reasons may name the person). The withdrawal is logged first, so a
//     deletion cut short still leaves a participant nobody records or analyses.
//   - Exclusion (ExcludeParticipant): the researcher's decision, with its reason; the analysis
//     leaves the participant out and says why. Nothing is deleted.
//   - AddNote: an experimenter's note; no lock (it may come from another terminal during a trial).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "attempt_outcome.hpp"
#include "dyad/status.hpp"
#include "study_file.hpp"

namespace dyad::study {

struct Attempt {
  int trial = 0, attempt = 0;
  std::string file, reason;  // reason: why this attempt repeats the trial (empty for the first)
  AttemptOutcome outcome = AttemptOutcome::kUnended;  // kUnended: started, never ended
  std::string incomplete;    // outcome incomplete: why (NoSubject)
  double seconds = 0;
  int exit = 0;              // the shell's number (128 + signal, 127 never started): for the log and old logs
  std::string ended;         // how the graph ended, in words ("" in logs written before it was kept)
  bool interrupted = false;  // RunAttempt: SIGINT/SIGTERM reached the runner (a person wants it all to stop)
};

struct Note {
  std::string time, text;
  int trial = 0;  // the trial running when it was written (0: none)
};

struct Session {
  std::string log;  // its path
  bool consent = false;
  bool withdrawn = false, data_deleted = false;  // consent withdrawn (later than any consent)
  std::string withdrawn_time;
  bool excluded = false;
  std::string exclusion_reason;  // of the latest exclusion or inclusion
  std::vector<Note> notes;
  std::vector<Attempt> attempts;  // in the order they started
  std::vector<std::string> problems;

  // The last attempt at `trial`, or null; the last complete one, or null.
  const Attempt* Last(int trial) const;
  const Attempt* Complete(int trial) const;
};

std::string AttemptFile(const Trial& t, int attempt);
std::string SessionLogPath(const Study& s, const std::string& participant);
Session ReadSession(const Study& s, const std::string& participant);

// Appends one event (its "time" is added) to the participant's log.
Status AppendSessionEvent(const Study& s, const std::string& participant, const std::string& json_object);
Status MarkConsent(const Study& s, const std::string& participant, const std::string& how);
Status AddNote(const Study& s, const std::string& participant, const std::string& text);
// `excluded` false: the participant is analysed again. The reason is required.
Status ExcludeParticipant(const Study& s, const std::string& participant, bool excluded, const std::string& reason);
// The caller holds the participant's SessionLock (no trial runs). Returns the files deleted.
StatusOr<int> WithdrawConsent(const Study& s, const std::string& participant, bool delete_data, const std::string& how);

struct AttemptRequest {
  std::string dyad;         // the dyad executable
  std::string participant;
  Trial trial;
  int attempt = 1;
  std::string reason;       // required for attempt > 1
  bool rehearsal = false;   // the rehearsal graph and its overrides, no consent needed
  std::vector<std::string> extra_sets;  // after the condition's (a rehearsal's seed)
  std::string run_log;      // the graph's output; empty: the terminal
  const std::atomic<bool>* stop = nullptr;  // set: stop the trial as SIGINT does (the study page's Stop)
  // A graph still there this long after `stop` is set gets the second stop (a second SIGINT,
  // then killed this long after with its group), as a second Ctrl-C would: `stop` is set once.
  std::chrono::milliseconds stop_grace{10000};
  // A timed trial's graph still running this long after its planned end (the wait for the
  // subject's page plus the duration) is stopped as if asked (then the second stop and the kill
  // as above): a graph that hangs while it ends would otherwise hold its participant for ever.
  // The attempt is then incomplete, saying so. Not for a rehearsal (simulated time) nor a trial
  // asked about after it (its end waits for the answers). 0: no limit.
  std::chrono::milliseconds overrun{60000};
  // The session's subject's link (subject_lobby.hpp): the study's subject_web binds this port
  // (> 0), and its clock waits up to wait_for_subject_s for the page (0: no wait).
  int subject_port = 0;
  double wait_for_subject_s = 0;
  bool start_anyway = false;  // started without the subject's page: the start line says so
  // Set: asked once the graph has ended; a reason ("" for none) makes an attempt that ended
  // stopped or complete incomplete, with that reason (`dyad study serve`: "the participant's
  // connection was lost for more than 60 s"). A failed attempt stays failed.
  std::function<std::string()> incomplete_reason;
  // False: SIGINT and SIGTERM are the caller's, who stops the trial through `stop` (`dyad study
  // serve` runs several attempts at once; their handlers would overwrite each other).
  bool own_signals = true;
  // After every other override and outside the graph hash: how the trial is served, not what it
  // is (`dyad study serve`: the subject's web component on loopback, paused without its page).
  std::vector<std::string> serve_sets;
};

// Why a trial's whole recording is no data ("" when someone took part): its graph has a subject's
// page (a `web_human` component) and its human/input holds not one engaged sample
// (kNoEngagedStep), or none at all. Empty trials are not data: the attempt's outcome is then
// incomplete, and `dyad study analyze` says the same of the recording (study_analysis.hpp).
constexpr const char* kNoEngagedStep = "no subject: not one engaged step (no subject's page connected, or nobody held)";
std::string NoSubject(const std::string& recording);

// Runs one attempt (see the contract); the returned attempt says how it ended.
StatusOr<Attempt> RunAttempt(const Study& s, const AttemptRequest& r);

// Why trial `k` (1-based) of `trials` may not start now ("" when it may).
std::string WhyNotStart(const Session& session, const std::vector<Trial>& trials, int k, const std::string& reason);

// Held for a whole session; refused (FailedPrecondition naming the lock) while another runner holds it.
class SessionLock {
 public:
  static StatusOr<SessionLock> Acquire(const Study& s, const std::string& participant);
  SessionLock(SessionLock&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  SessionLock& operator=(SessionLock&&) = delete;
  ~SessionLock();

 private:
  explicit SessionLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

// The `dyad run` command line of an attempt (for RunAttempt and its tests).
std::vector<std::string> AttemptCommand(const Study& s, const AttemptRequest& r);

}  // namespace dyad::study
