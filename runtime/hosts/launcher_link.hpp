// LauncherLink — the launchers of one graph placed on several hosts tell each other when a
// required process has failed for good, so that its failure ends the experiment on every host,
// not only its own (internal to the runtime; docs/distributed.md, "Supervision").
//
// The failed process cannot say so itself (a `kill -9` leaves no last word); its launcher can.
// Each launcher of a graph with hosts joins the graph's domain as a watcher (the graph's
// network section) and:
//   - on a required process of its host failing for good, publishes that process's state as
//     "failed" on dyad/launchers, which only launchers read (RELIABLE, TRANSIENT_LOCAL: a
//     launcher that matches late still gets it), and waits up to 2 s until a launcher of every
//     other host of the graph has matched and acknowledged it; and on dyad/processes too, for
//     `dyad status` and the recorder;
//   - reads dyad/launchers for a "failed" required process of the graph on another host, stamped
//     after this launcher started (an older one belongs to an earlier run of the same graph): its
//     launcher then stops its own processes (SIGTERM: they deactivate cleanly) and exits 1,
//     naming the process and its host.
// With `transport: tcp` each launcher also listens, on network.launcher_tcp_port at its host's
// address (validation requires it when processes are on several hosts), and dials the listeners
// named before its own (graph.hpp, tcp_listeners), so the launchers meet as the processes do.
// A whole machine that disappears (power, cable) says nothing: the others see its writers gone
// ("Health") and go on.
#pragma once

#include <map>

#include <cstdint>
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
  // Joins the graph's domain as the launcher of `host` (LauncherParticipantName(host)).
  static StatusOr<std::unique_ptr<LauncherLink>> Open(const Graph& graph, const std::string& host);
  ~LauncherLink();
  LauncherLink(const LauncherLink&) = delete;
  LauncherLink& operator=(const LauncherLink&) = delete;

  // Announces that `process` (of this host) failed for good after `restarts` restarts; returns
  // once a launcher of every other host acknowledged it, or after 2 s (false then).
  bool AnnounceFailure(const std::string& process, int restarts);

  // The first failure of a required process announced from another host, once:
  // "process 'mind' on host 'h2' failed for good (after 1 restart)".
  std::optional<std::string> TakeRemoteFailure();

  // Processes of other hosts that restarted since the last call (their dyad/processes
  // announcements carry a higher restart count than before), one line each:
  // "process 'mind' on host 'h2' restarted (restart 1): ..." (RestartNotice).
  std::vector<std::string> TakeRemoteRestarts();

 private:
  LauncherLink(const Graph& graph, std::string host);
  const Graph& graph_;
  std::string host_;
  int other_hosts_ = 0;     // hosts of the graph's processes besides this one
  int64_t started_ns_ = 0;  // wall clock at Open()
  bool reported_ = false;
  std::unique_ptr<DdsParticipant> participant_;
  TypedWriter* launchers_writer_ = nullptr;  // owned by participant_
  TypedWriter* processes_writer_ = nullptr;
  TypedReader* reader_ = nullptr;
  TypedReader* processes_reader_ = nullptr;
  std::map<std::string, uint32_t> restarts_seen_;  // process -> highest restart count announced
};

// What a restart means for the experiment: "its components' state is reset (mind: deliberator)"
// (a PV-RNN's context, a mixer's last command: a restarted process starts from its Configure).
std::string ResetClause(const Graph& graph, const std::string& process);
// "process 'mind' on host 'h2' restarted (restart 1): " + ResetClause.
std::string RestartNotice(const Graph& graph, const std::string& process, const std::string& host, uint32_t restarts);

}  // namespace dyad
