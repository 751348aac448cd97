#include "demonstrations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dyad::analyze {
namespace {

struct Sample {
  double x, y, t;  // t: stamp, ns
};

// Returns to the start after going away (see the header): the laps a segment holds.
int CountLaps(const std::vector<Sample>& seg) {
  double x0 = seg[0].x, x1 = seg[0].x, y0 = seg[0].y, y1 = seg[0].y;
  for (const auto& s : seg) x0 = std::min(x0, s.x), x1 = std::max(x1, s.x), y0 = std::min(y0, s.y), y1 = std::max(y1, s.y);
  const double extent = std::max(x1 - x0, y1 - y0);
  if (!(extent > 0)) return 1;
  int returns = 0;
  bool away = false;
  for (const auto& s : seg) {
    const double d = std::hypot(s.x - seg[0].x, s.y - seg[0].y);
    if (!away && d > 0.4 * extent) away = true;
    else if (away && d < 0.15 * extent) ++returns, away = false;
  }
  return std::max(1, returns);
}

double MedianSpacingMs(const std::vector<Sample>& seg) {
  std::vector<double> d;
  for (size_t i = 1; i < seg.size(); ++i) d.push_back((seg[i].t - seg[i - 1].t) * 1e-6);
  if (d.empty()) return 0;
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

Eigen::MatrixXd Resampled(const std::vector<Sample>& seg, int steps) {
  Eigen::MatrixXd m(2, steps);
  const double n1 = static_cast<double>(seg.size() - 1);
  for (int k = 0; k < steps; ++k) {
    const double u = n1 * k / (steps - 1);
    const size_t i = std::min(static_cast<size_t>(u), seg.size() - 2);
    const double f = u - static_cast<double>(i);
    m(0, k) = seg[i].x + f * (seg[i + 1].x - seg[i].x);
    m(1, k) = seg[i].y + f * (seg[i + 1].y - seg[i].y);
  }
  return m;
}

std::string Format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

std::string SegmentList(const std::vector<Segment>& segments) {
  std::string s;
  for (size_t i = 0; i < segments.size(); ++i)
    s += (i ? ", " : "") + std::to_string(i) + Format(" (at %.1f s, %.1f s long)", segments[i].start_s, segments[i].duration_s);
  return s;
}

}  // namespace

StatusOr<Demonstrations> DemonstrationsFromTable(const TopicTable& table, const DemonstrationOptions& o) {
  const int cx = table.Column("x"), cy = table.Column("y"), ce = table.Column("engaged"), ct = table.Column("header.stamp_ns");
  if (cx < 0 || cy < 0 || ce < 0)
    return Status::InvalidArgument("topic '" + o.topic + "' has no x, y and engaged fields (not HumanInput?)");
  std::vector<HumanSample> samples;
  samples.reserve(table.rows.size());
  for (const auto& row : table.rows) {
    HumanSample s;
    if (!ParseBool(row[ce], &s.engaged) || !ParseNumber(row[cx], &s.x) || !ParseNumber(row[cy], &s.y))
      return Status::DataLoss("topic '" + o.topic + "': a sample with unreadable x, y or engaged");
    if (ct >= 0) ParseNumber(row[ct], &s.stamp_ns);
    samples.push_back(s);
  }
  return DemonstrationsFromSamples(samples, o);
}

StatusOr<Demonstrations> DemonstrationsFromSamples(const std::vector<HumanSample>& samples, const DemonstrationOptions& o) {
  if (o.steps < 2) return Status::InvalidArgument("--steps must be >= 2, got " + std::to_string(o.steps));
  if (o.min_samples < 2) return Status::InvalidArgument("--min-samples must be >= 2, got " + std::to_string(o.min_samples));
  std::vector<std::vector<Sample>> runs(1);
  double first_t = NAN;
  for (const HumanSample& h : samples) {
    const Sample s{h.x, h.y, h.stamp_ns};
    if (std::isnan(first_t)) first_t = s.t;
    if (h.engaged && std::isfinite(s.x) && std::isfinite(s.y)) runs.back().push_back(s);
    else if (!runs.back().empty()) runs.emplace_back();
  }
  Demonstrations out;
  std::vector<const std::vector<Sample>*> qualifying;
  for (const auto& run : runs) {
    if (run.empty()) continue;
    if (static_cast<int>(run.size()) < o.min_samples) {
      ++out.skipped;
      continue;
    }
    qualifying.push_back(&run);
    out.segments.push_back({(run.front().t - first_t) * 1e-9, (run.back().t - run.front().t) * 1e-9, static_cast<int>(run.size()),
                            MedianSpacingMs(run), CountLaps(run)});
  }
  if (qualifying.empty())
    return Status::InvalidArgument("topic '" + o.topic + "': no engaged segment of at least " + std::to_string(o.min_samples) +
                                   " samples (" + std::to_string(out.skipped) + " shorter ones)");
  if (o.choose.empty()) {
    for (size_t i = 0; i < qualifying.size(); ++i) out.chosen.push_back(static_cast<int>(i));
  } else {
    for (int i : o.choose)
      if (i < 0 || i >= static_cast<int>(qualifying.size()))
        return Status::InvalidArgument(o.choose_name + ": no segment " + std::to_string(i) + "; " + o.source_name + " has " +
                                       std::to_string(qualifying.size()) + ": " + SegmentList(out.segments));
    out.chosen = o.choose;
  }
  out.dataset.name = "demonstrations";
  double period_sum = 0;
  for (size_t k = 0; k < out.chosen.size(); ++k) {
    const auto& seg = *qualifying[static_cast<size_t>(out.chosen[k])];
    const Segment& info = out.segments[static_cast<size_t>(out.chosen[k])];
    out.dataset.sequences.push_back(Resampled(seg, o.steps));
    const double step_ms = info.duration_s * 1e3 / (o.steps - 1);
    period_sum += step_ms;
    const std::string which = "primitive " + std::to_string(k) + " (segment " + std::to_string(out.chosen[k]) + ")";
    if (info.laps > 1)
      out.warnings.push_back(which + ": holds " + std::to_string(info.laps) + " laps of its shape, squeezed into one primitive of " +
                             std::to_string(o.steps) + " steps (draw one lap per hold, or pick segments with " + o.choose_name + ")");
    if (info.sample_period_ms > 0 && std::abs(step_ms / info.sample_period_ms - 1) > 0.2)
      out.warnings.push_back(which + Format(": drawn in %.0f samples %.0f ms apart, resampled to steps %.0f ms apart", info.samples,
                                            info.sample_period_ms, step_ms) +
                             ": the model learns it at another pace than it was drawn (" + o.steps_name + " " + std::to_string(info.samples) +
                             " keeps it)");
  }
  out.dataset.sampling_period_ms = period_sum / out.dataset.size();
  return out;
}

}  // namespace dyad::analyze
