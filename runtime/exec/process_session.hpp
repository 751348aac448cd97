// ProcessSession — what the executor of one process needs from the other processes of its graph,
// behind a small interface so that the executor stays about one process. The hosts layer
// implements it (hosts/graph_session.hpp: start barrier, clock sync, state announcements). A
// wall-clock graph of one process has a session that only announces its state (for `dyad
// status`; shared_start() false: it starts at once and ends as a lone process does); a stepped
// graph runs without one.
//
// Calls, all from the executor's Run() thread except Close():
//   Open(transport)         after the components' ports exist, before Configure
//   AwaitMatched(stopping)  after Configure, before Activate: blocks until this process's endpoints
//                           have matched their peers (so nothing it publishes is lost to them)
//   AwaitStart(stopping)    after every component's Activate: blocks until the agreed start
//                           (wall-clock ns; 0: stopped while waiting). The start is fixed only
//                           now, so that a component that waits in Activate (the web component's
//                           wait for the subject's page) delays the clock, not its first steps.
//   Started()             the clocks start: background work begins, "running" is announced
//   Heartbeat()           once per stats period while running; an error fails the process
//   Stopping()            the run ends (before any component is deactivated)
//   Close()               stops every thread that writes on the transport; idempotent, also
//                         from the executor's destructor, before the transport goes
#pragma once

#include <cstdint>
#include <functional>

#include <dyad/status.hpp>

#include "dds/transport.hpp"

namespace dyad {

class ProcessSession {
 public:
  virtual ~ProcessSession() = default;
  virtual Status Open(Transport* transport) = 0;
  // OK also when `stopping()` ended the wait (the executor checks it); an error fails the run.
  virtual Status AwaitMatched(const std::function<bool()>& /*stopping*/) { return Status::OK(); }
  virtual StatusOr<int64_t> AwaitStart(const std::function<bool()>& stopping) = 0;
  // When the graph started (valid after AwaitStart): the agreed instant, or for a process that
  // joined a running graph (restarted), the others' start, so it ends with them.
  virtual int64_t graph_start_ns() const = 0;
  virtual void Started() = 0;
  virtual Status Heartbeat() = 0;
  virtual void Stopping() = 0;
  virtual void Close() = 0;
  // True when the start (and so the end of --duration and --steps) is agreed with other processes.
  virtual bool shared_start() const { return true; }
};

}  // namespace dyad
