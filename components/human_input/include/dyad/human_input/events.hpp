// dyad/human_input/events.hpp: the scripted human's intervention events.
//
// In a graph, `events` is a YAML list of {start, end, primitive}:
//   events: [{start: 100, end: 250, primitive: 2}, {start: 400, end: 520, primitive: 5}]
// Steps count from 0 (the component's first step); an event covers steps start..end-1 (end is
// exclusive). Rules (each broken one is an error naming the event index and key):
//   - exactly the keys start, end, primitive, each an integer;
//   - 0 <= start < end;
//   - 0 <= primitive < the data set's number of primitives;
//   - sorted by start and not overlapping: start_i >= end_{i-1}.
#pragma once

#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::human_input {

struct InterventionEvent {
  int64_t start = 0;  // first step, inclusive
  int64_t end = 0;    // last step + 1
  int primitive = 0;  // data set sequence to trace
};

// Parses and checks the YAML text of the `events` parameter. `num_primitives` is the data set's
// number of primitives. Errors read "events[2].primitive = 9: must be in 0..6 (the data set has
// 7 primitives)", "events[1]: steps 240..299 overlap events[0] (steps 100..249)".
StatusOr<std::vector<InterventionEvent>> ParseEvents(const std::string& yaml_text, int num_primitives);

}  // namespace dyad::human_input
