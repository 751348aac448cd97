// LauncherLink — the launchers of one graph placed on several hosts tell each other when a
// required process has failed for good, so that its failure ends the experiment on every host,
// not only its own (internal to the runtime; docs/distributed.md, "Supervision").
//
// The failed process cannot say so itself (a `kill -9` leaves no last word); its launcher can.
// Each launcher of a graph with hosts joins the graph's domain as a watcher (UDP, the graph's
// network section) and:
//   - on a required process of its host failing for good, publishes that process's state as
//     "failed" on dyad/processes (RELIABLE, TRANSIENT_LOCAL, like the processes' own
//     announcements: a launcher that starts later hears it too, `dyad status` shows it and a
//     recorder keeps it) and waits up to 2 s for the other launchers to acknowledge it;
//   - reads dyad/processes for a "failed" state of a required process of the graph on another
//     host: its launcher then stops its own processes (SIGTERM: they deactivate cleanly) and
//     exits 1, naming the process and its host.
// A whole machine that disappears (power, cable) says nothing: the others see its writers gone
// ("Health") and go on.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

namespace dyad {

class DdsParticipant;
class TypedReader;
class TypedWriter;

class LauncherLink {
 public:
  // Joins the graph's domain as the launcher of `host`.
  static StatusOr<std::unique_ptr<LauncherLink>> Open(const Graph& graph, const std::string& host);
  ~LauncherLink();
  LauncherLink(const LauncherLink&) = delete;
  LauncherLink& operator=(const LauncherLink&) = delete;

  // Announces that `process` (of this host) failed for good after `restarts` restarts; returns
  // once every matched launcher acknowledged it, or after 2 s.
  void AnnounceFailure(const std::string& process, int restarts);

  // The first failure of a required process announced from another host, once:
  // "process 'mind' on host 'h2' failed for good (after 1 restart)".
  std::optional<std::string> TakeRemoteFailure();

 private:
  LauncherLink(const Graph& graph, std::string host);
  const Graph& graph_;
  std::string host_;
  bool reported_ = false;
  std::unique_ptr<DdsParticipant> participant_;
  TypedWriter* writer_ = nullptr;  // owned by participant_
  TypedReader* reader_ = nullptr;
};

}  // namespace dyad
