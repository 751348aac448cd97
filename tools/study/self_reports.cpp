#include "self_reports.hpp"

#include "closed_set.hpp"

namespace dyad::study {
namespace {

// One value a line, as the header lists them.
// clang-format off
constexpr tools::Named<SelfReports> kWhen[] = {
    {SelfReports::kAfterEvent, "after_event"},
    {SelfReports::kAfterTrial, "after_trial"},
    {SelfReports::kOff, "off"},
};
// clang-format on

}  // namespace

std::string_view ToString(SelfReports when) { return tools::NameOf(kWhen, when); }

StatusOr<SelfReports> ParseSelfReports(std::string_view word) {
  if (auto w = tools::ValueOf(kWhen, word)) return *w;
  return Status::InvalidArgument("must be " + tools::NamesOf(kWhen));
}

}  // namespace dyad::study
