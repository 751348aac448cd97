#include "subject_channel.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <nlohmann/json.hpp>

#include "json_limits.hpp"

namespace dyad::web {
namespace {
using json = nlohmann::json;
constexpr uint32_t kStateChannel = 1;
constexpr uint32_t kTaskChannel = 2;
constexpr uint32_t kQuestionChannel = 3;
}  // namespace

void SubjectChannel::SetServer(WebServer* server) { server_.store(server); }

std::string SubjectChannel::TaskJson() const {
  double left = 0;
  if (task_.countdown_s > 0)
    left = std::max(0.0, task_.countdown_s - std::chrono::duration<double>(std::chrono::steady_clock::now() - task_.countdown_start).count());
  json j{
      {"op", "task"}, {"target", task_.target}, {"message", task_.message}, {"countdown_s", left}, {"practice", task_.practice}};
  if (task_.time_s > 0)  // added for #46: the trial's time left (a page that does not know it ignores it)
    j["time_left_s"] =
        std::max(0.0, task_.time_s - std::chrono::duration<double>(std::chrono::steady_clock::now() - task_.time_start).count());
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

void SubjectChannel::SendToAll(uint32_t channel, const std::string& frame) {
  std::vector<ClientId> pages;
  {
    MutexLock lock(mutex_);
    pages = pages_;
  }
  if (WebServer* server = server_.load())
    for (ClientId c : pages) server->SendLatest(c, channel, frame, /*binary=*/false);
}

void SubjectChannel::SetTask(const Task& task) {
  std::string frame;
  {
    MutexLock lock(mutex_);
    task_ = task;
    frame = TaskJson();
  }
  SendToAll(kTaskChannel, frame);
}

std::string SubjectChannel::QuestionJson() const {
  const int of = static_cast<int>(questions_.size());
  if (asked_ >= questions_.size()) return json{{"op", "question"}, {"segment", -1}, {"of", of}}.dump();
  auto points = [](const Trace& path) {
    json out = json::array();
    for (const auto& xy : path) out.push_back({xy[0], xy[1]});
    return out;
  };
  const Question& q = questions_[asked_];
  return json{{"op", "question"}, {"segment", static_cast<int>(asked_)}, {"of", of}, {"stroke", points(q.stroke)}, {"robot", points(q.robot)}}
      .dump(-1, ' ', false, json::error_handler_t::replace);
}

void SubjectChannel::EndSteering() {
  MutexLock lock(mutex_);
  EndSteeringLocked();
}

void SubjectChannel::EndSteeringLocked() {
  if (trial_over_) return;
  trial_over_ = true;
  if (steering_ != 0) sink_(last_x_, last_y_, false);  // a hold ends now
}

void SubjectChannel::AskAfterTrial(std::vector<Question> questions) {
  std::string frame;
  {
    MutexLock lock(mutex_);
    if (asking_) return;
    EndSteeringLocked();
    asking_ = true;
    questions_ = std::move(questions);
    asked_ = 0;
    frame = QuestionJson();
  }
  SendToAll(kQuestionChannel, frame);
}

size_t SubjectChannel::pages() const {
  MutexLock lock(mutex_);
  return pages_.size();
}

bool SubjectChannel::steered() const {
  MutexLock lock(mutex_);
  return steering_ != 0;
}

SubjectChannel::PointerDelays SubjectChannel::pointer_delays() const {
  MutexLock lock(mutex_);
  return delays_;
}

namespace {
double WallNowMs() {
  return std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
}
}  // namespace

double SubjectChannel::WallMs() const { return options_.wall_ms ? options_.wall_ms() : WallNowMs(); }

void SubjectChannel::BroadcastState(double x, double y) {
  WebServer* server = server_.load();
  if (server == nullptr) return;
  std::vector<ClientId> pages;
  {
    MutexLock lock(mutex_);
    pages = pages_;
  }
  if (pages.empty()) return;
  const std::string frame = json{{"op", "state"}, {"x", x}, {"y", y}}.dump();
  for (ClientId c : pages) server->SendLatest(c, kStateChannel, frame, /*binary=*/false);
}

void SubjectChannel::SendRole(ClientId client, bool steering) {
  if (WebServer* server = server_.load()) server->SendText(client, json{{"op", "role"}, {"steering", steering}}.dump());
}

void SubjectChannel::OnOpen(ClientId client, Role role) {
  bool steering = false;
  ClientId demoted = 0;
  std::string task;
  {
    MutexLock lock(mutex_);
    task = TaskJson();
    pages_.push_back(client);
    roles_[client] = role;
    // The subject's page steers before the experimenter's: an experimenter who opened /subject
    // first (to check it) must not keep the steering once the participant's page comes.
    const bool experimenter_steers = steering_ != 0 && roles_[steering_] == Role::kExperimenter;
    if (role != Role::kViewer && (steering_ == 0 || (role == Role::kSubject && experimenter_steers))) {
      if (steering_ != 0) {
        demoted = steering_;
        sink_(last_x_, last_y_, false);  // the experimenter's hold ends now
      }
      steering_ = client, steering = true;
    }
  }
  if (demoted != 0) SendRole(demoted, false);
  json prims = json::array();
  for (const auto& p : options_.primitives) {
    json pts = json::array();
    for (const auto& xy : p) pts.push_back({xy[0], xy[1]});
    prims.push_back(pts);
  }
  WebServer* server = server_.load();
  if (server == nullptr) return;
  server->SendText(client, json{{"op", "hello"},
                                {"steering", steering},
                                {"half_width", options_.half_width},
                                {"engage_key", options_.engage_key},
                                {"role", RoleName(role)},
                                {"primitives", prims},
                                {"names", options_.names},
                                {"watermark", options_.watermark},
                                {"ask", options_.ask && static_cast<bool>(report_)},
                                {"ask_after_hold_s", options_.ask_after_hold_s}}
                               .dump());
  server->SendText(client, task);
  // The question shown, read after the hello is queued: the hello resets a page, so a question
  // sent to this page before it (by AskAfterTrial meanwhile) is sent again after it.
  std::string question;
  {
    MutexLock lock(mutex_);
    if (asking_) question = QuestionJson();
  }
  if (!question.empty()) server->SendLatest(client, kQuestionChannel, question, /*binary=*/false);
}

Status SubjectChannel::OnText(ClientId client, std::string_view text) {
  const double handler_ms = WallMs();
  if (!JsonDepthWithin(text)) return Status::InvalidArgument("nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  const json j = json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Status::InvalidArgument("not a JSON object");
  auto op = j.find("op");
  if (op == j.end() || !op->is_string()) return Status::InvalidArgument("no \"op\" string");
  if (*op == "pointer") return OnPointer(client, j, handler_ms);
  if (*op == "steer") return OnSteer(client);
  if (*op == "self_report") return OnSelfReport(client, j);
  return Status::InvalidArgument("unknown op");
}

// {"op": "pointer", "x", "y", "engaged"[, "wall", "t"]}: the steering page's pointer, published
// (clamped to the workspace); a watching page's is ignored. "wall" adds to the pointer delays,
// "t" is acknowledged.
Status SubjectChannel::OnPointer(ClientId client, const json& j, double handler_ms) {
  auto x = j.find("x"), y = j.find("y"), engaged = j.find("engaged");
  if (x == j.end() || y == j.end() || engaged == j.end() || !x->is_number() || !y->is_number() || !engaged->is_boolean())
    return Status::InvalidArgument("pointer: needs numbers \"x\", \"y\" and a boolean \"engaged\"");
  const double px = x->get<double>(), py = y->get<double>();
  if (!std::isfinite(px) || !std::isfinite(py)) return Status::InvalidArgument("pointer: x and y must be finite");
  // The page clamps to the workspace; a position outside it is clamped here too.
  const double h = options_.half_width;
  bool ack = false;
  {
    MutexLock lock(mutex_);
    if (roles_[client] == Role::kViewer) return Status::FailedPrecondition("pointer: a viewer's token may not steer");
    if (client != steering_) return Status::OK();  // a watching page: ignored
    last_x_ = std::clamp(px, -h, h);
    last_y_ = std::clamp(py, -h, h);
    sink_(last_x_, last_y_, engaged->get<bool>() && !trial_over_);  // after the trial nobody steers
    if (auto wall = j.find("wall"); wall != j.end() && wall->is_number() && delays_.total.size() < 100000) {
      const double event_ms = wall->get<double>(), published_ms = WallMs();
      delays_.total.push_back(published_ms - event_ms);
      if (WebServer* server = server_.load(); server != nullptr && server->message_received_ns() > 0) {
        const double received_ms = static_cast<double>(server->message_received_ns()) / 1e6;
        delays_.page_to_socket.push_back(received_ms - event_ms);
        delays_.socket_to_handler.push_back(handler_ms - received_ms);
        delays_.handler_to_published.push_back(published_ms - handler_ms);
      }
    }
    if (auto t = j.find("t"); t != j.end() && t->is_number() && (acked_ != client || handler_ms - acked_ms_ >= kAckIntervalMs)) {
      acked_ = client;
      acked_ms_ = handler_ms;
      ack = true;
    }
  }
  if (ack)
    if (WebServer* server = server_.load()) server->SendText(client, json{{"op", "ack"}, {"t", j["t"].get<double>()}}.dump());
  return Status::OK();
}

// {"op": "steer"}: this page takes the steering over; the previous steerer's hold ends.
Status SubjectChannel::OnSteer(ClientId client) {
  ClientId previous;
  {
    MutexLock lock(mutex_);
    if (roles_[client] == Role::kViewer) return Status::FailedPrecondition("steer: a viewer's token may not steer");
    previous = steering_;
    if (previous == client) return Status::OK();
    steering_ = client;
    sink_(last_x_, last_y_, false);  // the previous steerer's hold ends now
  }
  if (previous != 0) SendRole(previous, false);
  SendRole(client, true);
  return Status::OK();
}

// {"op": "self_report", "choice"[, "segment"]}: the subject's answer, during the trial or (to
// the question shown, by its segment) after it.
Status SubjectChannel::OnSelfReport(ClientId client, const json& j) {
  auto choice = j.find("choice");
  const int last = static_cast<int>(options_.primitives.size()) - 1;
  if (choice == j.end() || !choice->is_number_integer() || choice->get<int64_t>() < -1 || choice->get<int64_t>() > last)
    return Status::InvalidArgument("self_report: needs an integer \"choice\" in -1.." + std::to_string(last) +
                                   " (a primitive, or -1: something else)");
  auto segment = j.find("segment");
  if (segment != j.end() && (!segment->is_number_integer() || segment->get<int64_t>() < 0))
    return Status::InvalidArgument("self_report: \"segment\" must be the index of the question answered (an integer >= 0)");
  std::string next;
  bool stale = false;
  {
    MutexLock lock(mutex_);
    if (roles_[client] == Role::kViewer) return Status::FailedPrecondition("self_report: a viewer's token may not answer");
    if (client != steering_ || !report_) return Status::OK();  // nobody asked this page
    if (!trial_over_) {
      if (!options_.ask) return Status::OK();
      return report_(static_cast<int>(choice->get<int64_t>()), -1);
    }
    // After the trial: only an answer to the question shown counts. Another (a second click, a
    // stale page's) is ignored, and that page is shown the question again (it hid its own).
    if (!asking_) return Status::OK();
    if (segment == j.end() || asked_ >= questions_.size() || segment->get<int64_t>() != static_cast<int64_t>(asked_)) {
      stale = true;
    } else {
      if (Status s = report_(static_cast<int>(choice->get<int64_t>()), static_cast<int>(asked_)); !s.ok()) return s;
      ++asked_;
    }
    next = QuestionJson();
  }
  if (stale) {
    if (WebServer* server = server_.load()) server->SendLatest(client, kQuestionChannel, next, /*binary=*/false);
  } else {
    SendToAll(kQuestionChannel, next);
  }
  return Status::OK();
}

Status SubjectChannel::OnBinary(ClientId, std::span<const uint8_t>) {
  return Status::InvalidArgument("binary frames are not part of this protocol");
}

void SubjectChannel::OnClose(ClientId client) {
  ClientId promoted = 0;
  {
    MutexLock lock(mutex_);
    std::erase(pages_, client);
    roles_.erase(client);
    if (client != steering_) return;
    sink_(last_x_, last_y_, false);  // the subject left: disengaged at once
    steering_ = 0;
    for (const Role preferred : {Role::kSubject, Role::kExperimenter})  // a subject's page first
      for (ClientId page : pages_)
        if (steering_ == 0 && roles_[page] == preferred) steering_ = page;
    promoted = steering_;
  }
  if (promoted != 0) SendRole(promoted, true);
}

}  // namespace dyad::web
