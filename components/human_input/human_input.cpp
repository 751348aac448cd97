#include "human_input.hpp"

namespace dyad::human_input {

void HumanSynthetic::Describe(ComponentSpec& spec) {
  spec.Summary("A scripted human: during listed events engages and traces a data set primitive, else disengaged.");
  spec.RequiredParam("dataset", ParamType::kString).Path().Doc("NRL data set folder whose primitives are traced");
  spec.YamlParam("events", "[]")
      .Doc("list of {start, end, primitive}: steps start..end-1 engaged tracing that primitive; sorted, not overlapping");
  spec.Param("noise_std", 0.0).Min(0).Unit("workspace units").Doc("Gaussian noise per axis while engaged (seeded)");
  spec.Param("lag", int64_t{0}).Min(0).Unit("steps").Doc("the trace runs this many steps behind the event's clock");
  spec.Output<msg::HumanInput>("out").Doc("position and engaged flag, one sample per step");
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
  human_ = std::make_unique<SyntheticHuman>(std::move(data.value()), std::move(events.value()), o);
  out_ = &ctx.output<msg::HumanInput>("out");
  return Status::OK();
}

Status HumanSynthetic::Step(const StepInfo& info) {
  const HumanSample s = human_->Step(static_cast<int64_t>(info.index));
  sample_.x(s.x);
  sample_.y(s.y);
  sample_.engaged(s.engaged);
  return out_->Publish(sample_);
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
