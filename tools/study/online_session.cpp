#include "online_session.hpp"

#include <filesystem>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "attempt_end.hpp"

namespace dyad::study {
namespace {

using Json = nlohmann::json;

constexpr const char* kDeclined = "You did not agree to take part, so the study ends here. Thank you for your time.";
constexpr const char* kWithdrawn = "You have withdrawn from this study: nothing more is recorded. Thank you for your time.";
constexpr const char* kEnded = "The experimenter has ended this session. Thank you for your time.";
constexpr const char* kDone = "The study is complete. Thank you for taking part! Your completion code:";

// 10 characters from A-Z and 2-9 (no 0/O, 1/I: a code read and typed by a person).
std::string NewCode() {
  static constexpr char kAlphabet[] = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789";
  std::random_device rd;
  std::uniform_int_distribution<size_t> pick(0, sizeof kAlphabet - 2);
  std::string code;
  for (int i = 0; i < 10; ++i) code += kAlphabet[pick(rd)];
  return code;
}

// Why attempt `a` is repeated, in words a participant's log reader understands.
std::string RepeatReason(const Attempt& a) {
  const std::string n = "attempt " + std::to_string(a.attempt);
  switch (a.outcome) {
    case AttemptOutcome::kUnended:
      return "the server restarted during " + n;
    case AttemptOutcome::kIncomplete:
      return n + " was incomplete: " + a.incomplete;
    case AttemptOutcome::kStopped:
      return n + " was stopped";
    case AttemptOutcome::kFailed:
      return n + " " + FailedLine(a.ended, a.exit, a.seconds);
    case AttemptOutcome::kComplete:
      break;
  }
  return n + " is repeated";
}

}  // namespace

OnlineEvents ReadOnlineEvents(const std::string& log) {
  OnlineEvents out;
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    const Json j = Json::parse(line, nullptr, false);
    if (!j.is_object() || !j.contains("event") || !j["event"].is_string()) continue;  // ReadSession names bad lines
    const std::string event = j["event"];
    if (event == "declined") out.declined = true;
    else if (event == "consent") out.declined = false;
    else if (event == "completed" && j.contains("code") && j["code"].is_string()) out.code = j["code"];
    else if (event == "session_ended") out.ended = j.contains("reason") && j["reason"].is_string() ? j["reason"] : "(no reason)";
    else if (event == "session_resumed") out.ended.clear();
  }
  return out;
}

OnlineSession::OnlineSession(const Study& s, std::string participant)
    : study_(s), participant_(std::move(participant)), trials_(s.TrialsOf(participant_)) {}

OnlineSession::Phase OnlineSession::PhaseOf(const Session& session, const OnlineEvents& events) const {
  const bool declined = events.declined;
  if (session.withdrawn || !events.ended.empty()) return Phase::kRefused;
  if (study_.consent_required && !session.consent) return declined ? Phase::kRefused : Phase::kConsent;
  for (const Trial& t : trials_)
    if (!session.Complete(t.number)) return Phase::kWaiting;
  return Phase::kDone;
}

OnlineSession::Phase OnlineSession::phase() const {
  return PhaseOf(ReadSession(study_, participant_), ReadOnlineEvents(SessionLogPath(study_, participant_)));
}

std::string OnlineSession::PageFrame() {
  const Session session = ReadSession(study_, participant_);
  const OnlineEvents events = ReadOnlineEvents(session.log);
  switch (PhaseOf(session, events)) {
    case Phase::kConsent:
      return Json{{"op", "consent"}, {"text", study_.online.consent_text}}.dump();
    case Phase::kRefused:
      return Json{{"op", "refused"},
                  {"message", session.withdrawn       ? kWithdrawn
                              : !events.ended.empty() ? kEnded
                                                      : kDeclined}}
          .dump();
    case Phase::kDone:
      return DoneFrame();
    case Phase::kWaiting:
      break;
  }
  const std::optional<Planned> next = Next();
  if (!next) return DoneFrame();
  const std::string of = std::to_string(next->trial.number) + " of " + std::to_string(trials_.size());
  std::string message = next->trial.number == 1 && next->attempt == 1
                            ? "Welcome. Press the button when you are ready to start trial " + of + "."
                            : "Thank you. Trial " + of + " comes next: press the button when you are ready.";
  if (next->attempt > 1)
    message = "Trial " + of + " starts again (the last try did not finish). Press the button when you are ready.";
  return Json{{"op", "waiting"}, {"message", message}, {"ready", {{"label", "Start trial " + of}}}}.dump();
}

std::string OnlineSession::DoneFrame() {
  auto code = CompletionCode();
  return Json{
      {"op", "done"},
      {"message", code.ok() ? kDone : "The study is complete. Thank you for taking part! (" + code.status().message() + ")"},
      {"code", code.ok() ? *code : ""}}
      .dump();
}

Status OnlineSession::Consent(bool agree) {
  const Session session = ReadSession(study_, participant_);
  if (session.withdrawn)
    return Status::FailedPrecondition(participant_ + " withdrew consent: a new consent is marked in the lab only");
  if (agree) return session.consent ? Status::OK() : MarkConsent(study_, participant_, "agreed on the consent page online");
  return AppendSessionEvent(study_, participant_, R"({"event":"declined","how":"declined on the consent page online"})");
}

std::optional<OnlineSession::Planned> OnlineSession::Next() const {
  const Session session = ReadSession(study_, participant_);
  if (session.withdrawn || (study_.consent_required && !session.consent)) return std::nullopt;
  for (const Trial& t : trials_) {
    if (session.Complete(t.number)) continue;
    Planned p{t, 1, ""};
    if (const Attempt* last = session.Last(t.number)) {
      p.attempt = last->attempt + 1;
      p.reason = RepeatReason(*last);
    }
    std::error_code ec;
    while (std::filesystem::exists(std::filesystem::symlink_status(AttemptFile(t, p.attempt), ec))) ++p.attempt;
    return p;
  }
  return std::nullopt;
}

StatusOr<std::string> OnlineSession::CompletionCode() {
  MutexLock lock(code_mutex_);
  const OnlineEvents events = ReadOnlineEvents(SessionLogPath(study_, participant_));
  if (!events.code.empty()) return events.code;
  const std::string code = study_.online.completion_code.empty() ? NewCode() : study_.online.completion_code;
  if (Status st = AppendSessionEvent(study_, participant_, Json{{"event", "completed"}, {"code", code}}.dump()); !st.ok())
    return st;
  return code;
}

void OnlineSession::PageOpened() {
  MutexLock lock(mutex_);
  page_ = true;
  gone_since_.reset();
}

void OnlineSession::PageClosed(Clock::time_point now) {
  MutexLock lock(mutex_);
  page_ = false;
  gone_since_ = now;
}

void OnlineSession::PageFinished() {
  MutexLock lock(mutex_);
  page_ = false;
  gone_since_.reset();
}

bool OnlineSession::page() const {
  MutexLock lock(mutex_);
  return page_;
}

OnlineSession::Clock::duration OnlineSession::LostFor(Clock::time_point now) const {
  MutexLock lock(mutex_);
  if (page_ || !gone_since_) return Clock::duration::zero();
  return now - *gone_since_;
}

bool OnlineSession::Live(Clock::time_point now, bool trial_running) const {
  MutexLock lock(mutex_);
  if (page_ || trial_running) return true;
  return gone_since_ && now - *gone_since_ < std::chrono::duration<double>(study_.online.reconnect_s);
}

}  // namespace dyad::study
