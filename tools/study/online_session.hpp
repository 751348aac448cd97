// tools/study/online_session.hpp: one participant's session of `dyad study serve` (docs/study.md,
// "A study online"), as a state machine without a network: what their page is told between
// trials, what their next attempt is, and when their page has been gone too long.
//
// Everything but the connection's bookkeeping comes from the session log (study_session.hpp) at
// each call, so a restarted server goes on where the participant was:
//   - consent required and not marked (and not declined): the consent page
//     {"op":"consent","text":...} (the study's online.consent); Consent(true) marks it ("how":
//     "agreed on the consent page online"), Consent(false) logs {"event":"declined"}: a polite end.
//   - consent (or none required), trials left: {"op":"waiting","message":...,"ready":{"label":
//     "Start trial k of n"}}; Next() is the attempt Ready starts: the plan's next trial not
//     complete (WhyNotStart's order), attempt 1, or after an earlier attempt of it the next number
//     whose file is free, with an automatic reason from how the last one ended ("the server
//     restarted during attempt 2", "attempt 1 was incomplete: the participant's connection was
//     lost for more than 60 s", "attempt 1 failed: ...", "attempt 1 was stopped").
//   - every trial complete: {"op":"done","message":...,"code":...}; the completion code is the
//     study's online.completion_code, else one made for the participant (10 characters A-Z 2-9)
//     the first time, logged once ({"event":"completed","code":...}) and read back after.
//   - withdrawn, declined, or ended by the experimenter (ReadOnlineEvents' ended):
//     {"op":"refused","message":...} (nothing records for them).
// The connection (times given by the caller, so tests need no clock): PageOpened/PageClosed;
// LostFor(now) says, while the page is gone, how long; Live(now, trial_running): a page is
// connected, a trial runs, or the page left less than reconnect_s ago (what max_sessions counts).
//
// Thread-safe: every method may be called from any thread.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "dyad/thread_annotations.hpp"
#include "study_file.hpp"
#include "study_session.hpp"

namespace dyad::study {

// The events `dyad study serve` adds to a session log that ReadSession leaves to people:
// whether the latest consent answer is "declined", the code of a "completed" event ("" if none),
// and the reason of a {"event":"session_ended","reason":...} (the experimenter's overview
// stopped the session) not followed by a {"event":"session_resumed"} ("" if none).
struct OnlineEvents {
  bool declined = false;
  std::string code, ended;
};
OnlineEvents ReadOnlineEvents(const std::string& log);

class OnlineSession {
 public:
  using Clock = std::chrono::steady_clock;
  enum class Phase { kConsent, kWaiting, kDone, kRefused };

  // The attempt Ready starts (the caller adds the run's own fields).
  struct Planned {
    Trial trial;
    int attempt = 1;
    std::string reason;  // "" for attempt 1
  };

  OnlineSession(const Study& s, std::string participant);

  const std::string& participant() const { return participant_; }
  Phase phase() const;
  // The frame the page gets now, for the phase (JSON text).
  std::string PageFrame();
  // The page's answer on the consent page: marked, or "declined" logged.
  Status Consent(bool agree);
  // The next attempt, or nullopt when every trial is complete (or nothing may record).
  std::optional<Planned> Next() const;
  // The participant's completion code (see the contract): made and logged the first time.
  StatusOr<std::string> CompletionCode();

  void PageOpened();
  void PageClosed(Clock::time_point now);
  // Closed with nothing to come back for (done, refused): not live from now on.
  void PageFinished();
  bool page() const;
  // How long the page has been gone (zero while it is connected).
  Clock::duration LostFor(Clock::time_point now) const;
  bool Live(Clock::time_point now, bool trial_running) const;

 private:
  Phase PhaseOf(const Session& session, const OnlineEvents& events) const;
  std::string DoneFrame();

  const Study& study_;
  const std::string participant_;
  const std::vector<Trial> trials_;
  mutable Mutex mutex_;
  bool page_ GUARDED_BY(mutex_) = false;
  std::optional<Clock::time_point> gone_since_ GUARDED_BY(mutex_);  // unset: never connected
  Mutex code_mutex_;                                                // one code made and logged, however many pages ask at once
};

}  // namespace dyad::study
