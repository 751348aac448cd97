// The DDS domains of the trials `dyad study serve` runs at once: each trial's graph runs on a
// domain of its own while it runs (`--set domain_id=D`), taken from a range and given back when its
// graph has exited.
//
// Why: every graph on one domain discovers every other graph's participant and endpoints, however
// its run id keeps their samples apart. With all trials on the study graph's one domain, 48
// participants at once cost each graph about 800 warnings of other runs' writers and the machine a
// load average of 28 (41 deadline misses, pointer -> published p99 23 ms); one domain each: load
// average 1.2, no miss, p99 1.4 ms (README, "Participants at once").
//
// The range is `--domains FIRST-LAST`, else the study file's `online.domains: [FIRST, LAST]`, else
// the graph's own domain_id and the max_sessions - 1 after it. It must hold max_sessions domains
// (one per live session, and a running trial keeps its session live) within DDS's 0..232, so a
// free one is always there. A trial takes the domain given back longest ago: a graph's launcher
// has exited when its domain comes back, but a process of it that hangs on may still be ending
// (each has a process group of its own), and a domain given back just now is the last one to be
// used again. A TrialDomains is not thread-safe: its owner locks.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <string_view>

#include "dyad/status.hpp"

namespace dyad::study {

struct DomainRange {
  int first = 0, last = -1;  // inclusive
  int size() const { return last - first + 1; }
};

// "FIRST-LAST" (--domains), each 0..232, FIRST <= LAST.
StatusOr<DomainRange> ParseDomainRange(std::string_view text);

// The range for `max_sessions` trials at once: `given` (said to come from `given_by`, e.g.
// "--domains" or "s.yaml: online.domains"; "" where the caller's error names it already), else
// from `graph_domain` on. Its error names what to change.
StatusOr<DomainRange> TrialDomainRange(const std::optional<DomainRange>& given, const std::string& given_by, int graph_domain,
                                       int max_sessions);

class TrialDomains {
 public:
  explicit TrialDomains(DomainRange range);
  // The free domain given back longest ago (at first, in order from the range's first), now taken;
  // none: every one is in use.
  std::optional<int> Take();
  // `domain`, taken before, free again (another, or one free already, changes nothing).
  void Give(int domain);
  const DomainRange& range() const { return range_; }

 private:
  DomainRange range_;
  std::deque<int> free_;  // the longest free first
};

}  // namespace dyad::study
