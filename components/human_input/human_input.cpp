#include "human_input.hpp"

#include <cmath>

namespace dyad::human_input {

void HumanSynthetic::Describe(ComponentSpec& spec) {
  spec.Summary("A scripted human: during listed events engages and traces a data set primitive, else disengaged.");
  spec.RequiredParam("dataset", ParamType::kString).Path().Doc("NRL data set folder whose primitives are traced");
  spec.YamlParam("events", "[]")
      .Doc("list of {start, end, primitive}: steps start..end-1 engaged tracing that primitive; sorted, not overlapping");
  spec.Param("noise_std", 0.0).Min(0).Unit("workspace units").Doc("Gaussian noise per axis while engaged (seeded)");
  spec.Param("lag", int64_t{0}).Min(0).Unit("steps").Doc("the trace runs this many steps behind the event's clock");
  spec.Param("self_report_error", 0.0).Min(0).Max(1).Doc("probability that a self-report names another primitive (uniformly)");
  spec.Param("self_report_delay", 1.5).Range(0, 3600).Unit("s").Doc("from a release to its self-report");
  spec.Output<msg::HumanInput>("out").Doc("position and engaged flag, one sample per step");
  spec.Output<msg::SelfReport>("self_report").Optional().Doc(
      "after each event's release (and the delay): the primitive the human says it drew, as a study's subject answers");
}

Status HumanSynthetic::Configure(Context& ctx) {
  const std::string& dir = ctx.params().String("dataset");
  auto data = pvrnn::LoadNrlDataset(dir);
  if (!data.ok()) return Status::InvalidArgument("dataset: " + data.status().message());
  if (data->dofs() < 2)
    return Status::InvalidArgument("dataset: " + dir + " has " + std::to_string(data->dofs()) + " DOF, need x and y");
  auto events = ParseEvents(ctx.params().String("events"), data->size());
  if (!events.ok()) return events.status();
  SyntheticHumanOptions o;
  o.noise_std = ctx.params().Double("noise_std");
  o.lag = ctx.params().Int("lag");
  o.seed = ctx.seed();
  o.report_error = ctx.params().Double("self_report_error");
  report_delay_ns_ = std::llround(ctx.params().Double("self_report_delay") * 1e9);
  human_ = std::make_unique<SyntheticHuman>(std::move(data.value()), std::move(events.value()), o);
  out_ = &ctx.output<msg::HumanInput>("out");
  reports_ = &ctx.output<msg::SelfReport>("self_report");
  return Status::OK();
}

Status HumanSynthetic::Step(const StepInfo& info) {
  const HumanSample s = human_->Step(static_cast<int64_t>(info.index));
  sample_.x(s.x);
  sample_.y(s.y);
  sample_.engaged(s.engaged);
  if (Status st = out_->Publish(sample_); !st.ok()) return st;
  QueueReports(s, info.now_ns);
  return PublishDueReports(info.now_ns);
}

void HumanSynthetic::QueueReports(const HumanSample& s, int64_t now_ns) {
  for (const ReleasedEvent& r : s.released) {
    PendingReport p{.report = {}, .due_ns = now_ns + report_delay_ns_};
    p.report.choice(r.answer);
    p.report.segment_start_ns(r.event == segment_event_ ? segment_start_ns_ : now_ns);
    p.report.segment_end_ns(now_ns);
    pending_.push_back(std::move(p));
  }
  if (s.event >= 0 && s.event != segment_event_) {
    segment_event_ = s.event;
    segment_start_ns_ = now_ns;
  }
}

Status HumanSynthetic::PublishDueReports(int64_t now_ns) {
  while (!pending_.empty() && pending_.front().due_ns <= now_ns) {
    msg::SelfReport& r = pending_.front().report;
    r.response_s(static_cast<double>(now_ns - r.segment_end_ns()) * 1e-9);
    if (Status st = reports_->Publish(r); !st.ok()) return st;
    pending_.pop_front();
  }
  return Status::OK();
}

void HumanReplay::Describe(ComponentSpec& spec) {
  spec.Summary("Plays back a human track from CSV (columns x, y, engaged by header name), one row per step.");
  spec.RequiredParam("file", ParamType::kString).Path().Doc("CSV as `dyad bag export --csv` writes a HumanInput topic");
  spec.Output<msg::HumanInput>("out").Doc("one CSV row per step; the run is asked to stop after the last");
}

Status HumanReplay::Configure(Context& ctx) {
  ctx_ = &ctx;
  auto rows = LoadHumanTrack(ctx.params().String("file"));
  if (!rows.ok()) return Status::InvalidArgument("file: " + rows.status().message());
  rows_ = std::move(rows.value());
  out_ = &ctx.output<msg::HumanInput>("out");
  return Status::OK();
}

Status HumanReplay::Step(const StepInfo&) {
  if (next_ >= rows_.size()) return Status::OK();  // stop already requested
  const HumanTrackRow& r = rows_[next_++];
  sample_.x(r.x);
  sample_.y(r.y);
  sample_.engaged(r.engaged);
  if (Status s = out_->Publish(sample_); !s.ok()) return s;
  if (next_ == rows_.size()) ctx_->RequestStop("human_replay: replayed all " + std::to_string(rows_.size()) + " rows");
  return Status::OK();
}

}  // namespace dyad::human_input

DYAD_PLUGIN(registry) {
  registry.Add<dyad::human_input::HumanSynthetic>("human_synthetic");
  registry.Add<dyad::human_input::HumanReplay>("human_replay");
}
