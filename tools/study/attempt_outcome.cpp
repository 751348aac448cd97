#include "attempt_outcome.hpp"

#include <string>

#include "closed_set.hpp"

namespace dyad::study {
namespace {

// One value a line, as the header lists them.
// clang-format off
constexpr tools::Named<AttemptOutcome> kOutcomes[] = {
    {AttemptOutcome::kUnended, ""},
    {AttemptOutcome::kComplete, "complete"},
    {AttemptOutcome::kStopped, "stopped"},
    {AttemptOutcome::kFailed, "failed"},
    {AttemptOutcome::kIncomplete, "incomplete"},
};
// clang-format on

}  // namespace

std::string_view ToString(AttemptOutcome outcome) { return tools::NameOf(kOutcomes, outcome); }

StatusOr<AttemptOutcome> ParseAttemptOutcome(std::string_view word) {
  // An "end" event always has a word: the empty one (kUnended) is never read back.
  if (auto o = tools::ValueOf(kOutcomes, word); o && *o != AttemptOutcome::kUnended) return *o;
  return Status::InvalidArgument("outcome \"" + std::string(word) + "\": must be " + tools::NamesOf(kOutcomes));
}

}  // namespace dyad::study
