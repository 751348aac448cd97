// dyad/human_input/synthetic_human.hpp: the scripted human behind `human_synthetic`, without
// DDS (the component is a thin shell around it).
//
// At step k (0, 1, 2, ...):
//   - inside an event e (e.start <= k < e.end): engaged; with j = k - e.start the position is
//       data[e.primitive](:, max(j - lag, 0) mod T) + noise,   noise ~ N(0, noise_std^2) per axis,
//     i.e. the human starts at the primitive's first point, traces it `lag` steps behind the
//     event's clock (holding the first point for the first `lag` steps) and loops it while the
//     event lasts (the study's primitives are closed shapes);
//   - outside events: not engaged; the position is the last engaged position (before the first
//     event: the first point of the first event's primitive; no events: the origin). No noise.
// Noise comes from one std::mt19937_64 seeded with `seed`: same seed, same track.
//
// Self-reports (what a rehearsal's human says it drew): at step k = e.end the sample lists event e
// as released, with an answer: its primitive, or with probability `report_error` one of the other
// primitives, uniformly (the data set needs two or more for a wrong answer). The answers come
// from a second stream seeded from `seed`, so asking for them leaves the track as it was.
//
// Example:
//   SyntheticHuman h(dataset, events, {.noise_std = 0.5, .lag = 2, .seed = 7});
//   for (int64_t k = 0; k < 2000; ++k) { HumanSample s = h.Step(k); ... }
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "dyad/human_input/events.hpp"
#include "dyad/pvrnn/dataset.hpp"

namespace dyad::human_input {

struct SyntheticHumanOptions {
  double noise_std = 0.0;  // workspace units; REQUIRES >= 0
  int64_t lag = 0;         // steps; REQUIRES >= 0
  uint64_t seed = 1;
  double report_error = 0.0;  // probability of a wrong self-report; REQUIRES 0 <= p <= 1
};

// An event released at this step, and what the human says it was drawing.
struct ReleasedEvent {
  int event = -1;      // index into the events
  int primitive = -1;  // the primitive it traced (the truth)
  int answer = -1;     // the primitive it reports
};

struct HumanSample {
  double x = 0, y = 0;
  bool engaged = false;
  int event = -1;  // index of the event being traced, -1 when not engaged
  std::vector<ReleasedEvent> released;  // events whose end is this step (or passed since the last one asked)
};

class SyntheticHuman {
 public:
  // REQUIRES events as ParseEvents returns them for `data` (sorted, primitives in range),
  // data.dofs() >= 2 (x, y are the first two DOFs).
  SyntheticHuman(pvrnn::Dataset data, std::vector<InterventionEvent> events, const SyntheticHumanOptions& options);

  // The sample of step k. Steps must be asked in increasing order (the noise stream and the
  // event cursor advance).
  HumanSample Step(int64_t k);

 private:
  ReleasedEvent Release(size_t event);  // draws the answer

  pvrnn::Dataset data_;
  std::vector<InterventionEvent> events_;
  SyntheticHumanOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::mt19937_64 answers_;
  size_t next_event_ = 0;
  double last_x_ = 0, last_y_ = 0;
};

}  // namespace dyad::human_input
