#include "dyad/human_input/synthetic_human.hpp"

#include <algorithm>

namespace dyad::human_input {

SyntheticHuman::SyntheticHuman(pvrnn::Dataset data, std::vector<InterventionEvent> events,
                               const SyntheticHumanOptions& options)
    : data_(std::move(data)),
      events_(std::move(events)),
      options_(options),
      rng_(options.seed),
      answers_(options.seed ^ 0x5e1f'4e90'7b3c'11d5ULL) {
  if (!events_.empty()) {
    const Eigen::MatrixXd& first = data_.sequences[static_cast<size_t>(events_.front().primitive)];
    last_x_ = first(0, 0);
    last_y_ = first(1, 0);
  }
}

HumanSample SyntheticHuman::Step(int64_t k) {
  HumanSample s;
  while (next_event_ < events_.size() && events_[next_event_].end <= k) s.released.push_back(Release(next_event_++));
  if (next_event_ < events_.size() && events_[next_event_].start <= k) {
    const InterventionEvent& e = events_[next_event_];
    const Eigen::MatrixXd& seq = data_.sequences[static_cast<size_t>(e.primitive)];
    const int64_t src = std::max<int64_t>(k - e.start - options_.lag, 0) % seq.cols();
    s.x = seq(0, src);
    s.y = seq(1, src);
    if (options_.noise_std > 0) {
      s.x += options_.noise_std * normal_(rng_);
      s.y += options_.noise_std * normal_(rng_);
    }
    s.engaged = true;
    s.event = static_cast<int>(next_event_);
    last_x_ = s.x;
    last_y_ = s.y;
  } else {
    s.x = last_x_;
    s.y = last_y_;
  }
  return s;
}

ReleasedEvent SyntheticHuman::Release(size_t event) {
  ReleasedEvent r;
  r.event = static_cast<int>(event);
  r.primitive = events_[event].primitive;
  r.answer = r.primitive;
  const int n = data_.size();
  if (n > 1 && std::uniform_real_distribution<double>(0.0, 1.0)(answers_) < options_.report_error) {
    const int other = std::uniform_int_distribution<int>(0, n - 2)(answers_);  // one of the n - 1 others
    r.answer = other < r.primitive ? other : other + 1;
  }
  return r;
}

}  // namespace dyad::human_input
