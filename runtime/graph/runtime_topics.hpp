// The runtime's own topics: one table of {name, type, writer QoS, reader QoS, watcher QoS}.
// Every reader and writer of these topics takes its QoS from here, so the two sides cannot drift
// apart (a reader asking for more than its writer offers, e.g. TRANSIENT_LOCAL from a VOLATILE
// writer, silently never matches).
//
//   dyad/processes      each process's state (ready, running, stopping, failed): start barrier,
//                       launchers, `dyad status`; TRANSIENT_LOCAL so a late joiner hears it
//   dyad/launchers      the launchers' link: a required process failed for good
//   dyad/clock          clock-sync probes and answers between processes (best effort)
//   dyad/clock_offsets  each process's measured offsets to the others (TRANSIENT_LOCAL)
//   dyad/stats          every component's timing, once per stats period (TRANSIENT_LOCAL)
//   dyad/health         what a process did about endpoints discovery lost (hosts/endpoint_health)
//   dyad/param_requests live parameter changes asked for (`dyad param`, the experimenter's page,
//                       a param_script's output): every process reads them, the component's answers
//   dyad/params         the answers: applied (old and new value), refused (why), a value asked for
//
// `reader` is for the runtime's and the recorder's readers, which must not lose a sample;
// `watcher` for guests (`dyad status`, `hz`), which may drop samples but never slow a writer.
#pragma once

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "graph/topic_qos.hpp"

namespace dyad {

struct RuntimeTopic {
  const char* name;
  const TypeInfo& (*type)();
  TopicQos writer;
  TopicQos reader;
  TopicQos watcher;
};

namespace runtime_topics {

inline const RuntimeTopic kProcesses{
    .name = "dyad/processes",
    .type = &TypeInfoOf<msg::ProcessState>,
    .writer = {.reliability = Reliability::kReliable, .depth = 1, .transient_local = true},
    .reader = {.reliability = Reliability::kReliable, .depth = 64, .transient_local = true},
    .watcher = {.reliability = Reliability::kReliable, .depth = 64, .transient_local = true},
};

inline const RuntimeTopic kLaunchers{
    .name = "dyad/launchers",
    .type = &TypeInfoOf<msg::ProcessState>,
    .writer = {.reliability = Reliability::kReliable, .depth = 1, .transient_local = true},
    .reader = {.reliability = Reliability::kReliable, .depth = 64, .transient_local = true},
    .watcher = {.reliability = Reliability::kReliable, .depth = 64, .transient_local = true},
};

inline const RuntimeTopic kClock{
    .name = "dyad/clock",
    .type = &TypeInfoOf<msg::ClockProbe>,
    .writer = {.reliability = Reliability::kBestEffort, .depth = 32},
    .reader = {.reliability = Reliability::kBestEffort, .depth = 32},
    .watcher = {.reliability = Reliability::kBestEffort, .depth = 32},
};

// Offsets and stats keep their last samples (TRANSIENT_LOCAL, KEEP_LAST) so that `dyad status`
// has them the moment it joins instead of waiting for the next period. Its reader is reliable to
// get that history; with KEEP_LAST a writer never waits for it (an unacknowledged sample is
// simply replaced). 64 stats: one round of a process with up to 64 components.
inline const RuntimeTopic kClockOffsets{
    .name = "dyad/clock_offsets",
    .type = &TypeInfoOf<msg::ClockOffset>,
    .writer = {.reliability = Reliability::kReliable, .depth = 16, .transient_local = true},
    .reader = {.reliability = Reliability::kReliable, .depth = 16},
    .watcher = {.reliability = Reliability::kReliable, .depth = 256, .transient_local = true},
};

inline const RuntimeTopic kStats{
    .name = "dyad/stats",
    .type = &TypeInfoOf<msg::ComponentStats>,
    .writer = {.reliability = Reliability::kReliable, .depth = 64, .transient_local = true},
    .reader = {.reliability = Reliability::kReliable, .depth = 16},
    .watcher = {.reliability = Reliability::kReliable, .depth = 256, .transient_local = true},
};

inline const RuntimeTopic kHealth{
    .name = "dyad/health",
    .type = &TypeInfoOf<msg::HealthEvent>,
    .writer = {.reliability = Reliability::kReliable, .depth = 32},
    .reader = {.reliability = Reliability::kReliable, .depth = 32},
    .watcher = {.reliability = Reliability::kBestEffort, .depth = 256},
};

// Reliable both ways and deep: a request lost is a change silently not made, an answer lost is a
// change the recording does not show. Volatile: an old request must not be applied again by a
// process that joins later (a restarted one starts from the graph's values, and says so).
inline const RuntimeTopic kParamRequests{
    .name = "dyad/param_requests",
    .type = &TypeInfoOf<msg::ParamChange>,
    .writer = {.reliability = Reliability::kReliable, .depth = 64},
    .reader = {.reliability = Reliability::kReliable, .depth = 64},
    .watcher = {.reliability = Reliability::kReliable, .depth = 64},
};

inline const RuntimeTopic kParams{
    .name = "dyad/params",
    .type = &TypeInfoOf<msg::ParamChange>,
    .writer = {.reliability = Reliability::kReliable, .depth = 64},
    .reader = {.reliability = Reliability::kReliable, .depth = 64},
    .watcher = {.reliability = Reliability::kReliable, .depth = 64},
};

}  // namespace runtime_topics
}  // namespace dyad
