#include "trial_domains.hpp"

#include <algorithm>
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
      return Status::InvalidArgument((given_by.empty() ? "" : given_by + " ") + std::to_string(given->first) + "-" +
                                     std::to_string(given->last) + " holds " + std::to_string(given->size()) +
                                     (given->size() == 1 ? " domain" : " domains") + " for max_sessions " +
                                     std::to_string(max_sessions) +
                                     " (each live session's trial runs on a domain of its own): widen it, or lower max_sessions "
                                     "(--max-sessions, online.max_sessions)");
    return *given;
  }
  const DomainRange range{graph_domain, graph_domain + max_sessions - 1};
  if (range.last > kLastDomain)
    return Status::InvalidArgument(std::string("max_sessions ") + std::to_string(max_sessions) + " trials need domains " +
                                   std::to_string(range.first) + "-" + std::to_string(range.last) +
                                   " from the graph's domain_id on (each runs on a domain of its own; DDS has 0..232): "
                                   "set online.domains (or --domains) to a range within 0..232, or lower max_sessions "
                                   "(--max-sessions, online.max_sessions)");
  return range;
}

TrialDomains::TrialDomains(DomainRange range) : range_(range) {
  for (int d = range.first; d <= range.last; ++d) free_.push_back(d);
}

std::optional<int> TrialDomains::Take() {
  if (free_.empty()) return std::nullopt;
  const int d = free_.front();
  free_.pop_front();
  return d;
}

void TrialDomains::Give(int domain) {
  if (domain < range_.first || domain > range_.last || std::find(free_.begin(), free_.end(), domain) != free_.end()) return;
  free_.push_back(domain);
}

}  // namespace dyad::study
