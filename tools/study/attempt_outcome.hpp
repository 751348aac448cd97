// tools/study/attempt_outcome.hpp: how one attempt at a trial ended, as the session log's "end"
// event names it ("outcome", study_session.hpp) and every front end shows it.
//
// ToString gives the log's word; ParseAttemptOutcome reads it back, and for any other word says
// "must be complete, stopped, failed or incomplete" (the words of the same table, in
// attempt_outcome.cpp). kUnended has no word: it is never written (a start without its end).
#pragma once

#include <string_view>

#include "dyad/status.hpp"

namespace dyad::study {

enum class AttemptOutcome {
  kUnended,     // "" started, never ended: the session itself ended mid-trial ("interrupted")
  kComplete,    // "complete": the graph ended well and its recording is whole, with someone in it
  kStopped,     // "stopped": the experimenter ended a timed trial early
  kFailed,      // "failed": the graph exited non-zero other than after a stop, was killed, or left
                //   a recording cut short or none
  kIncomplete,  // "incomplete": the run ended well, but nobody took part (NoSubject says why)
};

std::string_view ToString(AttemptOutcome outcome);
StatusOr<AttemptOutcome> ParseAttemptOutcome(std::string_view word);

}  // namespace dyad::study
