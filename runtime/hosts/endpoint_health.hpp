// EndpointHealth — notices this process's endpoints that discovery lost while the run goes on,
// and heals them. Part of a process's session in a wall-clock graph of several processes
// (graph_session.cpp calls Check once per stats period, on the executor's thread).
//
// A reader or writer is starved when it matches fewer endpoints than the graph says it should,
// counting this process and every other process heard "running" on dyad/processes within the
// last kFreshS (a process that stopped, crashed or is cut off is not expected). That happens
// when discovery never tells one side about the other again: Fast DDS 2.9's discovery server
// orphans endpoints of a client it dropped and then saw return (docs/distributed.md, "A pulled
// cable"), while the processes themselves, and their other endpoints, are fine.
//
// Healing renews the starved endpoint (Transport::Renew: a new DDS entity, learnt afresh, behind
// the same port): a reader once it has been starved for kReaderS (lossless: the old one is
// still taken from for a while, dds_participant.hpp), a writer for kWriterS (readers that still
// matched the old writer miss what is written until they match the new one, so a writer is
// renewed only if renewing the readers on the other side did not help). Every renewal is logged
// with what was missing and reported (dyad/health); an endpoint still starved after kMaxRenewals
// renewals is an error: the process fails (its launcher's restart policy then decides).
//
// A process that hears none of the other required processes for `lost_s` (kLostS: two and a
// half of their heartbeats) while one should be running may have been forgotten by discovery
// as a whole (Fast DDS 2.9's server discards a returning client's announcement when it dropped
// it a moment before): renewing its endpoints would not help (discovery has no participant to
// attach them to), so it renews its participant (Transport::RenewParticipant: a new identity,
// every endpoint moved onto it) as soon as its network is up again, then at most once per
// `lost_s`. If the others really are gone this costs a new participant, and it never fails the
// process: their launchers say whether they failed.
//
// Not with transport: tcp: the renewed participant cannot listen on the process's tcp_port while
// the retired one holds it, and Fast DDS 2.9 then aborted the process at exit ("pure virtual
// method called", measured in tests/multihost_test.sh cut:tcp modes). There the silence is said
// once and endpoints are renewed as usual; TCP itself reconnects when the cable returns.
//
// Guests (watchers, `dyad echo`) add matches a writer may count: a starved writer whose topic
// also has a guest reader is not seen (its readers in the graph are, on their side).
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <set>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/status.hpp>

#include "dds/transport.hpp"

namespace dyad {

class EndpointHealth {
 public:
  static constexpr double kFreshS = 3;    // a "running" announcement older than this does not count
  static constexpr double kReaderS = 1;   // starved this long: a reader is renewed
  static constexpr double kWriterS = 2;   // starved this long: a writer is renewed
  static constexpr int kMaxRenewals = 5;  // per endpoint kind and topic; then the process fails
  // No other process heard this long (2.5 heartbeats): renew the participant.
  static constexpr double kLostS = 2.5;

  // What it did, as the event to publish (header and names left to the caller).
  using Report = std::function<void(msg::HealthEvent)>;
  EndpointHealth(const Graph& graph, std::string process, double lost_s, Report report = nullptr);

  // Compares each endpoint of `transport` with what `running` (the other processes heard
  // running) should give it; renews the ones starved long enough, lets go of finished renewals;
  // renews the participant after `silence_s` (StartBarrier::Peers) of lost_s. `now` is passed
  // for tests. An error when an endpoint cannot be healed.
  Status Check(Transport* transport, const std::set<std::string>& running, double silence_s = 0,
               std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());
  int renewals() const { return renewals_; }
  int participant_renewals() const { return participant_renewals_; }

 private:
  struct Starved {
    std::chrono::steady_clock::time_point since;
    int renewals = 0;
  };
  int Expected(const std::string& topic, bool writer, const std::set<std::string>& running) const;
  void RenewParticipant(Transport* transport, double silence_s, std::chrono::steady_clock::time_point now);
  Status CheckEndpoints(Transport* transport, const std::set<std::string>& running,
                        std::chrono::steady_clock::time_point now);

  void Tell(const std::string& topic, const char* endpoint, const char* action, int matched, int expected,
            double starved_s, int renewals);

  std::string process_;
  double lost_s_;
  Report report_;
  std::chrono::steady_clock::time_point participant_renewed_{};
  int participant_renewals_ = 0;
  bool postponed_ = false;  // a participant renewal waits for the network (said once)
  const bool tcp_;          // transport tcp: the participant is never renewed
  bool silence_said_ = false;
  // topic -> process -> endpoints the graph binds there (readers: inputs; writers: outputs);
  // dyad/processes has one of each in every process.
  std::map<std::string, std::map<std::string, int>> readers_in_, writers_in_;
  std::map<std::pair<std::string, bool>, Starved> starved_;  // (topic, writer)
  int renewals_ = 0;
};

}  // namespace dyad
