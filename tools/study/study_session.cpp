#include "study_session.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "attempt_end.hpp"
#include "child_process.hpp"
#include "dyad/mcap/reader.hpp"
#include "dyad/private_file.hpp"
#include "recording_tables.hpp"
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

// JSON text of `j`; text that is not UTF-8 (a reason typed in another encoding) is replaced, not thrown.
std::string Dump(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

const Condition& ConditionOf(const Study& s, const Trial& t) { return s.conditions[static_cast<size_t>(t.condition)]; }

// The overrides that make the experiment (the graph hash covers these): the condition's, the
// rehearsal's, the caller's (a seed).
std::vector<std::string> ExperimentSets(const Study& s, const AttemptRequest& r) {
  std::vector<std::string> sets = ConditionOf(s, r.trial).sets;
  if (r.rehearsal) sets.insert(sets.end(), s.rehearsal_sets.begin(), s.rehearsal_sets.end());
  sets.insert(sets.end(), r.extra_sets.begin(), r.extra_sets.end());
  if (!r.rehearsal) {  // the task on the subject's page (study_task.hpp)
    const std::vector<std::string> task = TaskSets(s.subject_web, ConditionOf(s, r.trial).task, r.trial.repetition);
    sets.insert(sets.end(), task.begin(), task.end());
  }
  return sets;
}

// All the overrides of an attempt, after `clock=...` and before the recorder's: with a person,
// the pages' too (whether to ask, the participant's own tokens).
std::vector<std::string> RunSets(const Study& s, const AttemptRequest& r) {
  std::vector<std::string> sets = ExperimentSets(s, r);
  if (r.rehearsal) return sets;
  sets.insert(sets.end(), s.page_sets.begin(), s.page_sets.end());
  for (const std::string& web : s.token_file_webs)
    sets.push_back(web + ".token_file=" + tools::YamlQuoted((fs::path(s.data) / r.participant / (web + "-tokens")).string()));
  if (!s.subject_web.empty() && s.duration_s > 0)  // the time left on the subject's page
    sets.push_back(s.subject_web + ".task_time_s=" + tools::SetText(YAML::Node(s.duration_s)));
  if (!s.subject_web.empty() && r.subject_port > 0) sets.push_back(s.subject_web + ".port=" + std::to_string(r.subject_port));
  if (!s.subject_web.empty() && r.wait_for_subject_s > 0)
    sets.push_back(s.subject_web + ".wait_for_subject_s=" + tools::SetText(YAML::Node(r.wait_for_subject_s)));
  sets.insert(sets.end(), r.serve_sets.begin(), r.serve_sets.end());
  return sets;
}

bool AskedAfterTrial(const Study& s) { return s.self_reports == SelfReports::kAfterTrial; }

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

std::atomic<int> g_stop_signals{0};  // lock-free: safe in a handler and read by another thread
static_assert(std::atomic<int>::is_always_lock_free);
extern "C" void OnStopSignal(int) { g_stop_signals.fetch_add(1); }

// SIGINT and SIGTERM only count while an attempt runs (the previous handlers come back after).
class StopSignals {
 public:
  StopSignals() {
    g_stop_signals.store(0);
    struct sigaction sa {};
    sa.sa_handler = OnStopSignal;
    sa.sa_flags = SA_RESTART;
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
    if (a.trial == trial && a.outcome == AttemptOutcome::kComplete) done = &a;
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
  int line_number = 0, running = 0;  // running: the trial started and not yet ended
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    if (line.empty()) continue;
    const std::string where = out.log + ":" + std::to_string(line_number) + ": ";
    try {
      const Json j = Json::parse(line);
      const std::string event = j.at("event").get<std::string>();
      if (event == "consent") {
        out.consent = true;
        out.withdrawn = out.data_deleted = false;
      } else if (event == "withdrawn") {
        out.consent = false;
        out.withdrawn = true;
        out.data_deleted = j.value("data", "kept") == "deleted";
        out.withdrawn_time = j.value("time", "");
      } else if (event == "excluded" || event == "included") {
        out.excluded = event == "excluded";
        out.exclusion_reason = j.at("reason").get<std::string>();
      } else if (event == "note") {
        out.notes.push_back(Note{j.value("time", ""), j.at("text").get<std::string>(), j.value("trial", running)});
      } else if (event == "start") {
        Attempt a;
        a.trial = running = j.at("trial").get<int>();
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
        auto outcome = ParseAttemptOutcome(j.at("outcome").get<std::string>());
        if (!outcome.ok()) out.problems.push_back(where + outcome.status().message() + " (taken as failed)");
        a->outcome = outcome.ok() ? *outcome : AttemptOutcome::kFailed;
        a->incomplete = j.value("incomplete", "");
        a->seconds = j.value("seconds", 0.0);
        a->exit = j.value("exit", 0);
        a->ended = j.value("ended", "");
        if (running == trial) running = 0;
      }  // other events are for people
    } catch (const std::exception& e) {
      out.problems.push_back(where + "not a session event: " + e.what());
    }
  }
  return out;
}

Status AppendSessionEvent(const Study& s, const std::string& participant, const std::string& json_object) {
  Json j = Json::parse(json_object, nullptr, false);  // (our own events: valid JSON)
  if (!j.is_object()) return Status::Internal("session event is not a JSON object: " + json_object);
  Json line = {{"time", UtcNow()}};
  line.update(j);
  const std::string path = SessionLogPath(s, participant);
  if (Status st = CreatePrivateDirectories(fs::path(path).parent_path().string()); !st.ok()) return st;
  std::error_code ec;
  const bool is_new = !fs::exists(path, ec);
  auto fd = OpenPrivateLog(path);
  if (!fd.ok()) return fd.status();
  const std::string text = Dump(line) + "\n";
  const ssize_t n = ::write(*fd, text.data(), text.size());
  const int sync_error = ::fdatasync(*fd) == 0 ? 0 : errno;
  ::close(*fd);
  if (n != static_cast<ssize_t>(text.size())) return Status::IOError(path, "cannot append to the session log");
  if (sync_error != 0)
    return Status::IOError(path, std::string("the session log could not be flushed to disk: ") + std::strerror(sync_error));
  if (!is_new) return Status::OK();
  // A new log: its entry in the participant's folder, and that folder's in the data folder (it
  // may be new too).
  if (Status st = SyncDirectory(fs::path(path).parent_path().string()); !st.ok()) return st;
  return SyncDirectory(fs::path(path).parent_path().parent_path().string());
}

std::string NoSubject(const std::string& recording) {
  auto reader = mcap::Reader::Open(recording);
  if (!reader.ok()) return "";  // not this rule's to judge: RunAttempt's own checks say failed
  bool subject_page = false;
  try {
    const YAML::Node components = YAML::Load(analyze::GraphMetadata(*reader, "yaml"))["components"];
    if (components && components.IsMap())
      for (const auto& c : components) subject_page = subject_page || (c.second["type"] && c.second["type"].as<std::string>() == "web_human");
  } catch (const YAML::Exception&) {
    return "";
  }
  if (!subject_page) return "";  // no person steers this graph (a test's, a rehearsal's)
  auto tables = analyze::ReadTables(*reader, {"human/input"});
  if (!tables.ok()) return "";
  const auto it = tables->find("human/input");
  if (it == tables->end() || it->second.size() == 0) return "no subject: no human input recorded (human/input)";
  const int engaged = it->second.Column("engaged");
  for (const auto& row : it->second.rows) {
    bool on = false;
    if (engaged >= 0 && analyze::ParseBool(row[static_cast<size_t>(engaged)], &on) && on) return "";
  }
  return kNoEngagedStep;
}

Status AddNote(const Study& s, const std::string& participant, const std::string& text) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) return Status::InvalidArgument("a note needs its text");
  // The trial under way, as ReadSession places notes: the last attempt started and not ended.
  const Session now = ReadSession(s, participant);
  Json note = {{"event", "note"}, {"text", text}};
  if (!now.attempts.empty() && now.attempts.back().outcome == AttemptOutcome::kUnended) note["trial"] = now.attempts.back().trial;
  return AppendSessionEvent(s, participant, Dump(note));
}

Status ExcludeParticipant(const Study& s, const std::string& participant, bool excluded, const std::string& reason) {
  if (reason.find_first_not_of(" \t\r\n") == std::string::npos)
    return Status::InvalidArgument(std::string(excluded ? "excluding " : "including ") + participant + " needs the reason");
  return AppendSessionEvent(s, participant, Dump(Json{{"event", excluded ? "excluded" : "included"}, {"reason", reason}}));
}

StatusOr<int> WithdrawConsent(const Study& s, const std::string& participant, bool delete_data, const std::string& how) {
  const Json line = {{"event", "withdrawn"}, {"how", how}, {"data", delete_data ? "deleted" : "kept"}};
  if (Status st = AppendSessionEvent(s, participant, Dump(line)); !st.ok()) return st;
  if (!delete_data) return 0;
  const fs::path dir = fs::path(s.data) / participant;
  int deleted = 0;
  std::error_code ec;
  std::vector<fs::path> entries;
  // The error_code increment: the range-for's would throw (the next entry unreadable, the folder gone).
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) entries.push_back(it->path());
  if (ec) return Status::IOError(dir.string(), "cannot list the participant's folder: " + ec.message());
  for (const fs::path& p : entries) {
    const std::string name = p.filename().string();
    if (name == "session.lock" || name == "session.log") continue;
    const auto n = fs::remove_all(p, ec);
    if (ec) return Status::IOError(p.string(), "cannot delete it: " + ec.message() + " (the withdrawal is logged; delete it by hand)");
    deleted += static_cast<int>(n);
  }
  // The log last, replaced whole: written and flushed beside it, then renamed over it, so a
  // power cut leaves the old log or the new one, never an empty one.
  const Json only = {{"time", UtcNow()}, {"event", "withdrawn"}, {"how", how}, {"data", "deleted"}, {"files_deleted", deleted}};
  const std::string log = SessionLogPath(s, participant), next = log + ".new";
  fs::remove(next, ec);
  auto fd = CreatePrivateFile(next, CreateMode::kNew);
  if (!fd.ok()) return fd.status();
  const std::string text = Dump(only) + "\n";
  const bool written = ::write(*fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) && ::fdatasync(*fd) == 0;
  const int write_error = written ? 0 : errno;
  ::close(*fd);
  if (!written) return Status::IOError(next, std::string("cannot write the new session log: ") + std::strerror(write_error));
  if (::rename(next.c_str(), log.c_str()) != 0)
    return Status::IOError(log, std::string("cannot replace the session log: ") + std::strerror(errno));
  if (Status st = SyncDirectory(dir.string()); !st.ok()) return st;
  return deleted;
}

Status MarkConsent(const Study& s, const std::string& participant, const std::string& how) {
  return AppendSessionEvent(s, participant, Dump(Json{{"event", "consent"}, {"how", how}}));
}

std::string WhyNotStart(const Session& session, const std::vector<Trial>& trials, int k, const std::string& reason) {
  if (k < 1 || k > static_cast<int>(trials.size())) return "there is no trial " + std::to_string(k);
  int next = 0;  // the first trial not complete
  for (const Trial& t : trials)
    if (!session.Complete(t.number)) {
      next = t.number;
      break;
    }
  if (session.Last(k)) return reason.empty() ? "trial " + std::to_string(k) + " was run before: say why it is repeated" : "";
  if (k != next) return "trial " + std::to_string(next) + " comes first (the plan's order)";
  return "";
}

StatusOr<SessionLock> SessionLock::Acquire(const Study& s, const std::string& participant) {
  const std::string dir = (fs::path(s.data) / participant).string(), path = dir + "/session.lock";
  if (Status st = CreatePrivateDirectories(dir); !st.ok()) return st;
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) return Status::IOError(path, std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return Status::FailedPrecondition(path, "another dyad study run holds " + participant + "'s session (one runner per participant)");
  }
  return SessionLock(fd);
}

SessionLock::~SessionLock() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

std::vector<std::string> AttemptCommand(const Study& s, const AttemptRequest& r) {
  const std::string graph = r.rehearsal ? s.rehearsal_graph : s.graph;
  const std::vector<std::string> sets = RunSets(s, r);
  const Condition& c = ConditionOf(s, r.trial);
  std::vector<std::string> args = {r.dyad, "run", graph};
  if (r.rehearsal) args.push_back("--quiet");
  // Asked after the trial, the subject's page ends the run once answered (its ask_after_s is the
  // duration, see LoadStudy); a rehearsal's synthetic people answer after each event.
  if (s.duration_s > 0 && (r.rehearsal || !AskedAfterTrial(s)))
    args.insert(args.end(), {"--duration", std::to_string(s.duration_s)});
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
      {"graph_hash", GraphHash(graph, ExperimentSets(s, r))}};
  std::string list;  // a YAML flow list of quoted scalars
  for (const auto& [key, value] : metadata) list += (list.empty() ? "[" : ", ") + tools::YamlQuoted(key + "=" + value);
  args.insert(args.end(), {"--set", s.recorder + ".file=" + tools::YamlQuoted(AttemptFile(r.trial, r.attempt)), "--set",
                           s.recorder + ".metadata=" + list + "]"});
  return args;
}

namespace {

// How attempt `a` ended, from its graph's end (`stopped`: a stop was forwarded to it, the first
// `first_stop_s` after it started) and its recording; the caller's reason may make it incomplete.
void SetOutcome(const Study& s, const AttemptRequest& r, const tools::ExitStatus& exit, bool stopped, double first_stop_s,
                Attempt* out) {
  Attempt& a = *out;
  a.exit = exit.ShellCode();
  a.ended = exit.ToString();
  // A trial without a duration ends when the experimenter stops it; a timed one stopped early is
  // stopped, unless the subject was answering after a full trial (the graph's start-up, a second
  // or two, counts in first_stop_s: a stop that much before the end counts too). A recording cut
  // short (a crash, a second stop) is never complete (attempt_end.hpp).
  const bool asking = !r.rehearsal && AskedAfterTrial(s) && first_stop_s >= s.duration_s;
  a.outcome = ClassifyGraphEnd({exit, stopped, s.duration_s > 0, asking});
  if (a.outcome == AttemptOutcome::kComplete) {
    bool whole = false;
    if (auto recording = mcap::Reader::Open(a.file); recording.ok()) whole = !recording->recovery().truncated;
    const std::string no_subject = whole ? NoSubject(a.file) : "";
    a.outcome = ClassifyRecording(whole, no_subject);
    if (a.outcome == AttemptOutcome::kIncomplete) a.incomplete = no_subject;
  }
  const std::string reason = r.incomplete_reason ? r.incomplete_reason() : "";
  if (!reason.empty() && (a.outcome == AttemptOutcome::kComplete || a.outcome == AttemptOutcome::kStopped)) {
    a.outcome = AttemptOutcome::kIncomplete;
    a.incomplete = reason;
  }
}

// Runs the attempt's graph to its end. One stop is forwarded as one SIGINT: the graph finishes
// its recording. A second stop (a graph that hangs while ending) is forwarded too: dyad then
// exits at once, losing at most its last chunk; a graph still there r.stop_grace (10 s) after
// it is killed, with its process group. A stop through r.stop comes once (nobody can press again, and
// a caller without its own signals has no second Ctrl-C to give): the graph still there
// r.stop_grace after it gets the second stop as if asked.
tools::ExitStatus RunGraph(const Study& s, const AttemptRequest& r, std::chrono::steady_clock::time_point t0, int* forwarded,
                           double* first_stop_s, bool* interrupted, bool* overran) {
  const bool guarded = r.overrun.count() > 0 && s.duration_s > 0 && !r.rehearsal && !AskedAfterTrial(s);
  const auto overdue_at = t0 + r.overrun +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(s.duration_s + r.wait_for_subject_s));
  std::optional<StopSignals> signals;
  if (r.own_signals) signals.emplace();
  tools::ChildOptions options;
  options.log = r.run_log;
  options.own_group = true;
  tools::ChildProcess graph(AttemptCommand(s, r), options);
  std::optional<std::chrono::steady_clock::time_point> stop_asked;  // when r.stop was first seen
  while (true) {
    if (std::optional<tools::ExitStatus> end = graph.Poll()) return *end;
    const auto now = std::chrono::steady_clock::now();
    const int signals_now = r.own_signals ? g_stop_signals.load() : 0;
    if (guarded && !stop_asked && now >= overdue_at) *overran = true;
    const bool stop = (r.stop && r.stop->load()) || *overran;
    if (stop && !stop_asked) stop_asked = now;
    const bool overdue = stop_asked && now - *stop_asked >= r.stop_grace;
    const int wanted = overdue ? 2 : std::min(2, signals_now + (stop ? 1 : 0));
    *interrupted = *interrupted || signals_now > 0;
    if (*forwarded == 0 && wanted > 0) *first_stop_s = std::chrono::duration<double>(now - t0).count();
    for (; *forwarded < wanted; ++*forwarded) graph.Signal(SIGINT);
    if (*forwarded == 2) return graph.Stop(r.stop_grace, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

StatusOr<Attempt> RunAttempt(const Study& s, const AttemptRequest& r) {
  const std::string who = r.participant + " trial " + std::to_string(r.trial.number);
  const Session session = ReadSession(s, r.participant);
  if (session.withdrawn)
    return Status::FailedPrecondition(who + ": " + r.participant + " withdrew consent (" + session.log +
                                      "): nothing is recorded for them unless a new consent is marked");
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
  if (r.start_anyway) start["start_anyway"] = "without the subject's page";
  if (Status st = AppendSessionEvent(s, r.participant, Dump(start)); !st.ok()) return st;

  const auto t0 = std::chrono::steady_clock::now();
  int forwarded = 0;        // SIGINTs sent to the graph
  double first_stop_s = 0;  // when the first was sent, from the graph's start
  bool overran = false;     // stopped by r.overrun
  const tools::ExitStatus exit = RunGraph(s, r, t0, &forwarded, &first_stop_s, &a.interrupted, &overran);
  a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  SetOutcome(s, r, exit, forwarded > 0, first_stop_s, &a);
  if (overran && a.outcome != AttemptOutcome::kFailed) {
    char late[64];
    std::snprintf(late, sizeof late, "%g s after its planned end (%g s)", std::chrono::duration<double>(r.overrun).count(),
                  s.duration_s + r.wait_for_subject_s);
    a.outcome = AttemptOutcome::kIncomplete;
    a.incomplete = std::string("its graph did not end by itself: still running ") + late + ", it was stopped";
  }
  Json end = {{"event", "end"},
              {"trial", a.trial},
              {"attempt", a.attempt},
              {"outcome", std::string(ToString(a.outcome))},
              {"seconds", std::round(a.seconds * 10) / 10},
              {"exit", a.exit},
              {"ended", a.ended}};
  if (!a.incomplete.empty()) end["incomplete"] = a.incomplete;
  if (Status st = AppendSessionEvent(s, r.participant, Dump(end)); !st.ok()) return st;
  return a;
}

}  // namespace dyad::study
