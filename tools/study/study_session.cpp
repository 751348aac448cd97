#include "study_session.hpp"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <thread>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "dyad/private_file.hpp"
#include "run_process.hpp"
#include "yaml_file.hpp"

#ifndef DYAD_VERSION
#define DYAD_VERSION "unknown"
#endif

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

const Condition& ConditionOf(const Study& s, const Trial& t) { return s.conditions[static_cast<size_t>(t.condition)]; }

// The overrides of an attempt, after `clock=...` and before the recorder's.
std::vector<std::string> RunSets(const Study& s, const AttemptRequest& r) {
  std::vector<std::string> sets = ConditionOf(s, r.trial).sets;
  if (r.rehearsal) sets.insert(sets.end(), s.rehearsal_sets.begin(), s.rehearsal_sets.end());
  else sets.insert(sets.end(), s.page_sets.begin(), s.page_sets.end());
  sets.insert(sets.end(), r.extra_sets.begin(), r.extra_sets.end());
  return sets;
}

std::string GraphHash(const std::string& graph, const std::vector<std::string>& sets) {
  std::ifstream in(graph, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  uint64_t h = tools::Fnv1a(text.str());
  for (const std::string& set : sets) h = tools::Fnv1a("\n--set " + set, h);
  char hex[20];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

volatile sig_atomic_t g_stop_requested = 0;
extern "C" void OnStopSignal(int) { g_stop_requested = 1; }

// SIGINT and SIGTERM only set a flag while an attempt runs (the previous handlers come back after).
class StopSignals {
 public:
  StopSignals() {
    g_stop_requested = 0;
    struct sigaction sa {};
    sa.sa_handler = OnStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

}  // namespace

const Attempt* Session::Last(int trial) const {
  const Attempt* last = nullptr;
  for (const Attempt& a : attempts)
    if (a.trial == trial) last = &a;
  return last;
}

const Attempt* Session::Complete(int trial) const {
  const Attempt* done = nullptr;
  for (const Attempt& a : attempts)
    if (a.trial == trial && a.outcome == "complete") done = &a;
  return done;
}

std::string AttemptFile(const Trial& t, int attempt) {
  if (attempt <= 1) return t.file;
  const fs::path f(t.file);
  return (f.parent_path() / (f.stem().string() + ".try" + std::to_string(attempt) + ".mcap")).string();
}

std::string SessionLogPath(const Study& s, const std::string& participant) {
  return (fs::path(s.data) / participant / "session.log").string();
}

Session ReadSession(const Study& s, const std::string& participant) {
  Session out;
  out.log = SessionLogPath(s, participant);
  std::ifstream in(out.log);
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (line.empty()) continue;
    const std::string where = out.log + ":" + std::to_string(line_number) + ": ";
    try {
      const Json j = Json::parse(line);
      const std::string event = j.at("event").get<std::string>();
      if (event == "consent") {
        out.consent = true;
      } else if (event == "start") {
        Attempt a;
        a.trial = j.at("trial").get<int>();
        a.attempt = j.at("attempt").get<int>();
        a.file = j.at("file").get<std::string>();
        a.reason = j.value("reason", "");
        out.attempts.push_back(std::move(a));
      } else if (event == "end") {
        const int trial = j.at("trial").get<int>(), attempt = j.at("attempt").get<int>();
        Attempt* a = nullptr;
        for (Attempt& x : out.attempts)
          if (x.trial == trial && x.attempt == attempt) a = &x;
        if (!a) {
          out.problems.push_back(where + "the end of trial " + std::to_string(trial) + " attempt " + std::to_string(attempt) +
                                 ", which never started");
          continue;
        }
        a->outcome = j.at("outcome").get<std::string>();
        a->seconds = j.value("seconds", 0.0);
        a->exit = j.value("exit", 0);
      }  // other events (notes) are for people
    } catch (const std::exception& e) {
      out.problems.push_back(where + "not a session event: " + e.what());
    }
  }
  return out;
}

Status AppendSessionEvent(const Study& s, const std::string& participant, const std::string& json_object) {
  Json j = Json::parse(json_object, nullptr, false);
  if (!j.is_object()) return Status::Internal("session event is not a JSON object: " + json_object);
  Json line = {{"time", UtcNow()}};
  line.update(j);
  const std::string path = SessionLogPath(s, participant);
  if (Status st = CreatePrivateDirectories(fs::path(path).parent_path().string()); !st.ok()) return st;
  auto fd = OpenPrivateLog(path);
  if (!fd.ok()) return fd.status();
  const std::string text = line.dump() + "\n";
  const ssize_t n = ::write(*fd, text.data(), text.size());
  ::close(*fd);
  if (n != static_cast<ssize_t>(text.size())) return Status::IOError(path, "cannot append to the session log");
  return Status::OK();
}

Status MarkConsent(const Study& s, const std::string& participant, const std::string& how) {
  return AppendSessionEvent(s, participant, Json{{"event", "consent"}, {"how", how}}.dump());
}

std::vector<std::string> AttemptCommand(const Study& s, const AttemptRequest& r) {
  const std::string graph = r.rehearsal ? s.rehearsal_graph : s.graph;
  const std::vector<std::string> sets = RunSets(s, r);
  const Condition& c = ConditionOf(s, r.trial);
  std::vector<std::string> args = {r.dyad, "run", graph};
  if (r.rehearsal) args.push_back("--quiet");
  if (s.duration_s > 0) args.insert(args.end(), {"--duration", std::to_string(s.duration_s)});
  if (r.rehearsal) args.insert(args.end(), {"--set", "clock=stepped"});
  for (const std::string& set : sets) args.insert(args.end(), {"--set", set});
  const std::vector<std::pair<std::string, std::string>> metadata = {
      {"study", s.name},
      {"participant", r.participant},
      {"condition", s.blind ? c.label : c.name},
      {"trial", std::to_string(r.trial.number)},
      {"attempt", std::to_string(r.attempt)},
      {"rehearsal", r.rehearsal ? "true" : "false"},
      {"dyad_version", DYAD_VERSION},
      {"graph_hash", GraphHash(graph, sets)}};
  std::string list;  // a YAML flow list of quoted scalars ('' is a quote inside one)
  for (const auto& [key, value] : metadata) {
    std::string entry = key + "=" + value, quoted;
    for (char ch : entry) quoted += ch == '\'' ? std::string("''") : std::string(1, ch);
    list += (list.empty() ? "['" : ", '") + quoted + "'";
  }
  args.insert(args.end(), {"--set", s.recorder + ".file=" + AttemptFile(r.trial, r.attempt), "--set", s.recorder + ".metadata=" + list + "]"});
  return args;
}

StatusOr<Attempt> RunAttempt(const Study& s, const AttemptRequest& r) {
  const std::string who = r.participant + " trial " + std::to_string(r.trial.number);
  const Session session = ReadSession(s, r.participant);
  if (!r.rehearsal && s.consent_required && !session.consent)
    return Status::FailedPrecondition(who + ": consent is required (consent_required in " + s.file +
                                      ") and not marked for " + r.participant + ": nothing was recorded");
  if (r.attempt > 1 && r.reason.empty()) return Status::InvalidArgument(who + ": a repetition needs its reason");
  Attempt a;
  a.trial = r.trial.number;
  a.attempt = r.attempt;
  a.file = AttemptFile(r.trial, r.attempt);
  a.reason = r.reason;
  std::error_code ec;
  if (fs::exists(fs::symlink_status(a.file, ec)))
    return Status::FailedPrecondition(a.file, "exists: a recording is never replaced (a repetition records beside it)");
  if (Status st = CreatePrivateDirectories(fs::path(a.file).parent_path().string()); !st.ok()) return st;
  Json start = {{"event", "start"}, {"trial", a.trial}, {"attempt", a.attempt}, {"file", a.file}};
  if (!a.reason.empty()) start["reason"] = a.reason;
  if (Status st = AppendSessionEvent(s, r.participant, start.dump()); !st.ok()) return st;

  const auto t0 = std::chrono::steady_clock::now();
  bool stopped = false;
  {
    StopSignals signals;
    const int pid = tools::StartProcess(AttemptCommand(s, r), r.run_log, true);
    a.exit = 127;
    // A stop is forwarded once: a second SIGINT makes dyad exit at once, losing its last chunk.
    while (pid >= 0 && !tools::ProcessEnded(pid, &a.exit)) {
      if ((g_stop_requested || (r.stop && r.stop->load())) && !stopped) {
        stopped = true;
        ::kill(pid, SIGINT);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // A trial without a duration ends when the experimenter stops it; a timed one stopped early is
  // incomplete. The graph's exit status after a stop is its answer to the signal, not a failure.
  if (stopped) a.outcome = s.duration_s > 0 ? "stopped" : "complete";
  else a.outcome = a.exit == 0 ? "complete" : "failed";
  if (a.outcome == "complete" && !fs::exists(a.file, ec)) a.outcome = "failed";
  Json end = {{"event", "end"}, {"trial", a.trial}, {"attempt", a.attempt}, {"outcome", a.outcome},
              {"seconds", std::round(a.seconds * 10) / 10}, {"exit", a.exit}};
  if (Status st = AppendSessionEvent(s, r.participant, end.dump()); !st.ok()) return st;
  return a;
}

}  // namespace dyad::study
