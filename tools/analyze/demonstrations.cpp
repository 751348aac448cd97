#include "demonstrations.hpp"

#include <cmath>

namespace dyad::analyze {

StatusOr<Demonstrations> DemonstrationsFromTable(const TopicTable& table, const DemonstrationOptions& o) {
  if (o.steps < 2) return Status::InvalidArgument("--steps must be >= 2, got " + std::to_string(o.steps));
  if (o.min_samples < 2) return Status::InvalidArgument("--min-samples must be >= 2, got " + std::to_string(o.min_samples));
  const int cx = table.Column("x"), cy = table.Column("y"), ce = table.Column("engaged"), ct = table.Column("header.stamp_ns");
  if (cx < 0 || cy < 0 || ce < 0)
    return Status::InvalidArgument("topic '" + o.topic + "' has no x, y and engaged fields (not HumanInput?)");
  struct Sample {
    double x, y, t;
  };
  std::vector<std::vector<Sample>> segments(1);
  for (const auto& row : table.rows) {
    bool engaged = false;
    Sample s{0, 0, 0};
    if (!ParseBool(row[ce], &engaged) || !ParseNumber(row[cx], &s.x) || !ParseNumber(row[cy], &s.y))
      return Status::DataLoss("topic '" + o.topic + "': a sample with unreadable x, y or engaged");
    if (ct >= 0) ParseNumber(row[ct], &s.t);
    if (engaged && std::isfinite(s.x) && std::isfinite(s.y)) segments.back().push_back(s);
    else if (!segments.back().empty()) segments.emplace_back();
  }
  Demonstrations out;
  out.dataset.name = "demonstrations";
  double period_sum = 0;
  for (const auto& seg : segments) {
    if (seg.empty()) continue;
    if (static_cast<int>(seg.size()) < o.min_samples) {
      ++out.skipped;
      continue;
    }
    Eigen::MatrixXd m(2, o.steps);
    const double n1 = static_cast<double>(seg.size() - 1);
    for (int k = 0; k < o.steps; ++k) {
      const double u = n1 * k / (o.steps - 1);
      const size_t i = std::min(static_cast<size_t>(u), seg.size() - 2);
      const double f = u - static_cast<double>(i);
      m(0, k) = seg[i].x + f * (seg[i + 1].x - seg[i].x);
      m(1, k) = seg[i].y + f * (seg[i + 1].y - seg[i].y);
    }
    out.dataset.sequences.push_back(std::move(m));
    period_sum += (seg.back().t - seg.front().t) * 1e-6 / (o.steps - 1);
  }
  if (out.dataset.sequences.empty())
    return Status::InvalidArgument("topic '" + o.topic + "': no engaged segment of at least " + std::to_string(o.min_samples) +
                                   " samples (" + std::to_string(out.skipped) + " shorter ones)");
  out.dataset.sampling_period_ms = period_sum / out.dataset.size();
  return out;
}

}  // namespace dyad::analyze
