// tools/study/self_reports.hpp: when the subject's page asks the subject about their holds (the
// study file's `self_reports:`, given to each `web` component of the graph as its own
// `self_reports` parameter, with the same word).
//
// ToString gives the file's word; ParseSelfReports reads it, and for any other word says "must be
// after_event, after_trial or off" (the words of the same table, in self_reports.cpp).
#pragma once

#include <string_view>

#include "dyad/status.hpp"

namespace dyad::study {

enum class SelfReports {
  kAfterEvent,  // "after_event" (the default): after each release
  kAfterTrial,  // "after_trial": once the trial's time is up, about each hold, and the trial ends
                //   when the subject has answered
  kOff,         // "off": never
};

std::string_view ToString(SelfReports when);
StatusOr<SelfReports> ParseSelfReports(std::string_view word);

}  // namespace dyad::study
