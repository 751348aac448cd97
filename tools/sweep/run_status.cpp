#include "run_status.hpp"

#include "closed_set.hpp"

namespace dyad::sweep {
namespace {

// One value a line, as the header lists them.
// clang-format off
constexpr tools::Named<RunStatus> kStatuses[] = {
    {RunStatus::kOk, "ok"},
    {RunStatus::kIncomplete, "incomplete"},
    {RunStatus::kFailed, "failed"},
    {RunStatus::kMissing, "missing"},
};
// clang-format on

}  // namespace

std::string_view ToString(RunStatus status) { return tools::NameOf(kStatuses, status); }

StatusOr<RunStatus> ParseRunStatus(std::string_view word) {
  if (auto s = tools::ValueOf(kStatuses, word)) return *s;
  return Status::InvalidArgument("must be " + tools::NamesOf(kStatuses));
}

}  // namespace dyad::sweep
