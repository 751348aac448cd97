#include "trial_domains.hpp"

#include <charconv>

namespace dyad::study {
namespace {

constexpr int kLastDomain = 232;  // DDS over UDP: 7400 + 250 * 232 + offsets stays under 65536

std::optional<int> DomainId(std::string_view text) {
  int v = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < 0 || v > kLastDomain) return std::nullopt;
  return v;
}

}  // namespace

StatusOr<DomainRange> ParseDomainRange(std::string_view text) {
  const size_t dash = text.find('-');
  const auto first = dash == std::string_view::npos ? std::nullopt : DomainId(text.substr(0, dash));
  const auto last = dash == std::string_view::npos ? std::nullopt : DomainId(text.substr(dash + 1));
  if (!first || !last || *first > *last)
    return Status::InvalidArgument(
        std::string(1, '\'').append(text).append("': want FIRST-LAST, two DDS domain ids in 0..232, FIRST <= LAST"));
  return DomainRange{*first, *last};
}

StatusOr<DomainRange> TrialDomainRange(const std::optional<DomainRange>& given, const std::string& given_by, int graph_domain,
                                       int max_sessions) {
  if (given) {
    if (given->size() < max_sessions)
      return Status::InvalidArgument(given_by + " " + std::to_string(given->first) + "-" + std::to_string(given->last) +
                                     " holds " + std::to_string(given->size()) + " domains for max_sessions " +
                                     std::to_string(max_sessions) +
                                     " (each live session's trial runs on a domain of its own): widen it or lower max_sessions");
    return *given;
  }
  const DomainRange range{graph_domain, graph_domain + max_sessions - 1};
  if (range.last > kLastDomain)
    return Status::InvalidArgument(std::string("max_sessions ") + std::to_string(max_sessions) + " trials need domains " +
                                   std::to_string(range.first) + "-" + std::to_string(range.last) +
                                   " from the graph's domain_id on (each runs on a domain of its own; DDS has 0..232): "
                                   "set online.domains (or --domains) to a range within 0..232, or lower max_sessions");
  return range;
}

std::optional<int> TrialDomains::Take() {
  for (size_t i = 0; i < used_.size(); ++i)
    if (!used_[i]) {
      used_[i] = true;
      return range_.first + static_cast<int>(i);
    }
  return std::nullopt;
}

void TrialDomains::Give(int domain) {
  const int i = domain - range_.first;
  if (i >= 0 && i < static_cast<int>(used_.size())) used_[static_cast<size_t>(i)] = false;
}

}  // namespace dyad::study
