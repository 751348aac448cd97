/// StatsTable — the experimenter's table of step statistics: the newest ComponentStats of every
/// component of the graph, from `dyad/stats` (any process of the graph).
///
/// Only the graph's own (process, component) pairs, given at construction, are kept: a peer
/// publishing `dyad/stats` under other names (forged, or another graph on the domain) cannot
/// grow the table or the page. Samples that do not decode (not from a dyad runtime of this
/// version) are ignored. Thread-safe: Add runs on the subscription's thread, Json on the
/// component's step.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <set>
#include <span>
#include <string>
#include <utility>

#include <dyad/msg/types.hpp>

namespace dyad::web {

class StatsTable {
 public:
  using Key = std::pair<std::string, std::string>;  // (process, component)
  explicit StatsTable(std::set<Key> graphs_own) : graphs_own_(std::move(graphs_own)) {}
  // One dyad/stats sample, as CDR with its encapsulation header.
  void Add(std::span<const uint8_t> cdr);
  // {"op":"stats","rows":[{process, component, steps, mean_ms, p99_ms, max_ms, misses}]}.
  std::string Json() const;
  size_t size() const;

 private:
  const std::set<Key> graphs_own_;
  mutable std::mutex mutex_;
  std::map<Key, msg::ComponentStats> rows_;
};

}  // namespace dyad::web
