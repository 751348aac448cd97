/// Human input sources: where the experiment's human comes from when nobody sits at the robot.
///
/// @component human_synthetic
/// rate_hz: periodic (study: 10)
/// outputs: out (HumanInput): position (workspace units) and engaged flag, one sample per step
/// params:
///   dataset (string, required): NRL data set folder (LoadNrlDataset) whose primitives are traced
///   events (yaml, []): list of {start, end, primitive}: steps start..end-1 engaged, tracing
///       that primitive (see dyad/human_input/events.hpp for the rules; errors name the index)
///   noise_std (double, 0, units): Gaussian noise per axis while engaged, seeded from ctx.seed()
///   lag (int, 0, steps): the trace runs this many steps behind the event's clock
///   self_report_error (double, 0, 0..1): probability that a self-report names another primitive
///   self_report_delay (double, 1.5, s): from a release to its self-report
/// optional outputs: self_report (SelfReport): after each event's release (and the delay), what
///   the human says it drew: the event's primitive, or a wrong one (a rehearsal of a study)
/// Outside events: engaged = false at the last engaged position (see synthetic_human.hpp).
/// @endcomponent
///
/// @component human_replay
/// rate_hz: periodic (study: 10)
/// outputs: out (HumanInput): one CSV row per step
/// params:
///   file (string, required): CSV with columns x, y, engaged found by header name (as
///       `dyad bag export --csv` writes a HumanInput topic)
/// After the last row the run is asked to stop (RequestStop).
/// @endcomponent
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

#include "dyad/human_input/human_track.hpp"
#include "dyad/human_input/synthetic_human.hpp"

namespace dyad::human_input {

class HumanSynthetic final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  // Self-reports of released events, each published once its delay has passed.
  void QueueReports(const HumanSample& s, int64_t now_ns);
  Status PublishDueReports(int64_t now_ns);

  std::unique_ptr<SyntheticHuman> human_;
  Output<msg::HumanInput>* out_ = nullptr;  // owned by the runtime
  Output<msg::SelfReport>* reports_ = nullptr;  // owned by the runtime; may be unbound
  msg::HumanInput sample_;
  int64_t report_delay_ns_ = 0;
  int segment_event_ = -1;  // the event being traced and the stamp of its first step
  int64_t segment_start_ns_ = 0;
  struct PendingReport {
    msg::SelfReport report;
    int64_t due_ns;
  };
  std::deque<PendingReport> pending_;
};

class HumanReplay final : public Component {
 public:
  static void Describe(ComponentSpec& spec);
  Status Configure(Context& ctx) override;
  Status Step(const StepInfo& info) override;

 private:
  Context* ctx_ = nullptr;
  std::vector<HumanTrackRow> rows_;
  size_t next_ = 0;
  Output<msg::HumanInput>* out_ = nullptr;  // owned by the runtime
  msg::HumanInput sample_;
};

}  // namespace dyad::human_input
