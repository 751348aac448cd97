#include "online_front.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "online_session.hpp"
#include "study_links.hpp"
#include "ws_client.hpp"
#include "yaml_file.hpp"

namespace dyad::study {
namespace {

using Json = nlohmann::json;

constexpr const char* kOpenTwice = "This link is already open in another window.";
constexpr const char* kComeBack =
    "Please come back later: the study has as many participants as it can take right now. Your link stays valid.";
constexpr const char* kHeldElsewhere =
    "Please come back later: your session is open elsewhere right now (the lab). Your link stays valid.";
constexpr std::chrono::milliseconds kRelayRetry{200};
// A page's frames queued for the front's thread beyond this (it is far behind, or the page
// floods): the page is closed rather than its frames held in memory.
constexpr size_t kQueuedBytes = 1 << 20;
// A relayed frame the trial's graph cannot take within this (it stopped reading) drops the relay
// (the page reconnects) rather than holding the thread that relays it (the page's worker, or the
// front's one thread, every page's).
constexpr std::chrono::milliseconds kRelayWrite{100};
// A trial whose graph failed this many times in a row (a broken graph or machine) is not offered
// again until `dyad study serve` restarts: the participant is asked to come back later.
constexpr int kFailuresInARow = 3;

int64_t WallNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// What the front reads of a relayed pointer sample, without a JSON parser (every frame of every
// page passes here, on a civetweb worker's small stack): the page's frames are JSON.stringify's,
// {"op":"pointer","x":..,"y":..,"engaged":true,"wall":..,...}. A frame written otherwise (spaces
// around the colons of "op") is relayed all the same; the overview then shows no "engaged" for it.
struct PointerScan {
  std::optional<bool> engaged;
  double wall_ms = -1;  // the page's stamp; negative: none
};
PointerScan ScanPointer(std::string_view text) {
  PointerScan scan;
  if (text.find("\"op\":\"pointer\"") == std::string_view::npos) return scan;
  auto value_of = [text](std::string_view key) -> std::string_view {
    size_t at = text.find(key);
    if (at == std::string_view::npos) return {};
    at = text.find_first_not_of(" \t", at + key.size());
    if (at == std::string_view::npos || text[at] != ':') return {};
    at = text.find_first_not_of(" \t", at + 1);
    return at == std::string_view::npos ? std::string_view{} : text.substr(at);
  };
  const std::string_view engaged = value_of("\"engaged\"");
  if (engaged.starts_with("true")) scan.engaged = true;
  else if (engaged.starts_with("false")) scan.engaged = false;
  const std::string_view wall = value_of("\"wall\"");
  double ms = 0;
  if (std::from_chars(wall.data(), wall.data() + wall.size(), ms).ec == std::errc() && std::isfinite(ms) && ms >= 0)
    scan.wall_ms = ms;
  return scan;
}

// One line on stdout for the pointer delays through the front (nothing when none was relayed);
// empties both.
void LogPointerDelays(std::vector<double>& to_worker_ms, std::vector<double>& to_relayed_ms) {
  if (to_worker_ms.empty()) return;
  auto median_p99 = [](std::vector<double>& ms) {
    std::sort(ms.begin(), ms.end());
    char text[64];
    std::snprintf(text, sizeof text, "median %.2f ms, p99 %.2f ms", ms[ms.size() / 2], ms[ms.size() * 99 / 100]);
    return std::string(text);
  };
  std::cout << "pointer hops through the front: page -> a worker has the frame " << median_p99(to_worker_ms)
            << "; -> relayed to the trial's graph " << median_p99(to_relayed_ms) << " (" << to_worker_ms.size() << " samples)"
            << std::endl;
  to_worker_ms.clear();
  to_relayed_ms.clear();
}
constexpr const char* kBroken =
    "Something went wrong on our side, and the study cannot go on right now. Please come back later: your link stays "
    "valid.";

// The port a trial's graph bound, from the file its web component wrote (port_file): 0 while the
// file is missing or not yet whole (one line ending in a newline).
int ReadPortFile(const std::string& file) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.empty() || text.back() != '\n') return 0;
  char* end = nullptr;
  const long port = std::strtol(text.c_str(), &end, 10);
  return end != text.c_str() && *end == '\n' && port > 0 && port <= 65535 ? static_cast<int>(port) : 0;
}

std::string Refused(const std::string& message) { return Json{{"op", "refused"}, {"message", message}}.dump(); }

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", s);
  return text;
}

}  // namespace

struct OnlineFront::Participant {
  Participant(const Study& s, const std::string& id) : id(id), session(s, id) {}
  const std::string id;
  OnlineSession session;
  std::atomic<bool> stop{false};
  std::mutex worker_mutex;  // StartTrial (the front's thread) and StopAll (the server's loop)
  std::thread worker;       // the running or last trial (under worker_mutex)
  // Under OnlineFront::mutex_:
  std::optional<SessionLock> lock;
  web::ClientId page = 0;                   // the page connected now (0: none)
  std::shared_ptr<web::WsClient> upstream;  // the relay to the trial's graph, while a trial runs
  bool running = false;
  int port = 0;           // the running trial's, once read from port_file (0: not yet)
  int domain = -1;        // the running trial's DDS domain, taken from domains_ (-1: none taken)
  std::string port_file;  // where the running trial's graph writes the port it bound
  std::string token, lost_reason;
  int ping_id = 0;
  Clock::time_point ping_sent{};
  Clock::time_point heard{};  // the page's last frame (its pongs included)
  double rtt_ms = -1;
  int failures = 0;       // attempts failed in a row (kFailuresInARow: none more)
  std::string view;       // the op of the view the page was sent last: "consent", "waiting" (else "")
  bool answered = false;  // the page answered that view: more answers ignored until the next view
  // For the experimenter's overview: the running attempt, the page's engagement, the end.
  int trial = 0, attempt = 0;
  std::string file, ended;
  std::optional<bool> engaged;
};

OnlineFront::OnlineFront(const Study& s, FrontOptions o) : study_(s), options_(std::move(o)), domains_(options_.domains) {
  for (const std::string& p : s.participants) {
    auto participant = std::make_unique<Participant>(s, p);
    participant->ended = ReadOnlineEvents(SessionLogPath(s, p)).ended;  // ended before a restart: shown, and resumable
    participants_.emplace(p, std::move(participant));
  }
  events_thread_ = std::thread([this] { Events(); });
}

OnlineFront::~OnlineFront() { StopAll(); }

void OnlineFront::Send(web::ClientId client, std::string text) {
  if (web::WebServer* server = server_.load()) server->SendText(client, std::move(text));
}

void OnlineFront::Close(web::ClientId client, int code, const std::string& reason) {
  if (web::WebServer* server = server_.load()) server->Close(client, code, reason);
}

OnlineFront::Participant* OnlineFront::Of(web::ClientId client) {
  MutexLock lock(mutex_);
  const auto it = clients_.find(client);
  return it == clients_.end() ? nullptr : it->second;
}

int OnlineFront::LiveLocked(Clock::time_point now) const {
  int n = 0;
  for (const auto& [id, p] : participants_) n += p->session.Live(now, p->running);
  return n;
}

int OnlineFront::live(Clock::time_point now) const {
  MutexLock lock(mutex_);
  return LiveLocked(now);
}

int OnlineFront::running() const {
  MutexLock lock(mutex_);
  int n = 0;
  for (const auto& [id, p] : participants_) n += p->running;
  return n;
}

std::string OnlineFront::Take(Participant& p, web::ClientId client, Clock::time_point now, bool final) {
  if (p.page != 0) return kOpenTwice;
  if (!final && !p.session.Live(now, p.running) && LiveLocked(now) >= options_.max_sessions) return kComeBack;
  if (!p.lock) {
    auto lock = SessionLock::Acquire(study_, p.id);
    if (!lock.ok()) return kHeldElsewhere;
    p.lock.emplace(std::move(*lock));
  }
  p.page = client;
  p.view.clear();
  p.answered = false;
  p.heard = now;
  p.session.PageOpened();
  clients_[client] = &p;
  return "";
}

// The ClientHandler calls, on civetweb's workers (OnText too: study serve's endpoint says its
// handler only queues): each only queues the event for the front's thread, never waiting for it.
void OnlineFront::OnOpen(web::ClientId client, web::Role) {
  web::WebServer* server = server_.load();
  const auto it = server ? participants_.find(server->who(client)) : participants_.end();
  if (it == participants_.end()) return Close(client, 1008, "not a participant");
  {
    MutexLock lock(events_mutex_);
    if (!events_stopped_) {
      opening_.insert(client);
      events_.push_back(Event{Event::Kind::kOpen, client, it->second.get(), {}});
      events_cv_.notify_one();
      return;
    }
  }
  Close(client, 1001, "the study's server is stopping");
}

Status OnlineFront::OnText(web::ClientId client, std::string_view text) {
  const int64_t received_ns = WallNs();
  if (RelayAtOnce(client, text, received_ns)) return Status::OK();
  MutexLock lock(events_mutex_);
  if (events_stopped_) return Status::OK();
  size_t& queued = queued_bytes_[client];
  if (queued + text.size() > kQueuedBytes) {
    queued_bytes_.erase(client);  // the server closes the page: its close comes next
    return Status::FailedPrecondition("the page sent more than the study's server could take in time");
  }
  queued += text.size();
  // A pong is the front's own (a round trip), never relayed: a page's later frames may overtake it.
  const bool ordered = text.find("\"pong\"") == std::string_view::npos;
  if (ordered) ++in_flight_[client];
  events_.push_back(Event{Event::Kind::kText, client, nullptr, std::string(text), received_ns, ordered});
  events_cv_.notify_one();
  return Status::OK();
}

void OnlineFront::OnClose(web::ClientId client) {
  MutexLock lock(events_mutex_);
  queued_bytes_.erase(client);
  if (events_stopped_ || opening_.erase(client) > 0) return;  // its open never handled: nothing to undo
  events_.push_back(Event{Event::Kind::kClose, client, nullptr, {}});
  events_cv_.notify_one();
}

void OnlineFront::Events() {
  UniqueLock lock(events_mutex_);
  while (true) {
    events_cv_.wait(lock.native(), [this] {
      events_mutex_.AssertHeld();
      return events_stopped_ || !events_.empty();
    });
    if (events_stopped_) return;
    Event e = std::move(events_.front());
    events_.pop_front();
    bool handle = true;
    if (e.kind == Event::Kind::kOpen) handle = opening_.erase(e.client) > 0;  // else closed while queued
    if (const auto queued = queued_bytes_.find(e.client); e.kind == Event::Kind::kText && queued != queued_bytes_.end()) {
      queued->second -= std::min(queued->second, e.text.size());
      if (queued->second == 0) queued_bytes_.erase(queued);
    }
    lock.Unlock();
    if (handle && e.kind == Event::Kind::kOpen) Open(*e.participant, e.client);
    else if (e.kind == Event::Kind::kText) Text(e.client, e.text, e.received_ns);
    else if (e.kind == Event::Kind::kClose) Closed(e.client);
    lock.Lock();
    if (const auto f = in_flight_.find(e.client); e.ordered && f != in_flight_.end() && --f->second == 0)
      in_flight_.erase(f);  // handled: the page's next frame may go at once
  }
}

void OnlineFront::Open(Participant& p, web::ClientId client) {
  std::string refused;
  bool running = false;
  web::ClientId silent = 0;  // p's page until now, silent too long: a connection dead without a close
  std::shared_ptr<web::WsClient> silent_relay;
  {
    MutexLock lock(mutex_);
    const Clock::time_point now = Clock::now();
    if (p.page != 0 && now - p.heard > 2 * options_.ping_interval + std::chrono::seconds(1)) {
      std::swap(silent, p.page);
      silent_relay = std::move(p.upstream);
      p.session.PageClosed(now);
    }
    refused = Take(p, client, now, false);
    running = p.running;
  }
  if (refused == kComeBack) {
    // Done, declined, withdrawn or ended: the page only hears that and is closed, taking no
    // session's place (reopening the link to see the code is not "come back later").
    const OnlineSession::Phase ph = p.session.phase();  // the log, read outside the lock
    if (ph == OnlineSession::Phase::kDone || ph == OnlineSession::Phase::kRefused) {
      MutexLock lock(mutex_);
      refused = Take(p, client, Clock::now(), true);
      running = p.running;
    }
  }
  if (silent_relay) silent_relay->Close();
  if (silent != 0) Close(silent, 1001, "replaced by a newer page of this link");
  if (!refused.empty()) {
    std::cout << p.id << ": a page refused: " << refused << std::endl;
    Send(client, Refused(refused));
    return Close(client, 1008, "refused");
  }
  if (!running) return SendPhase(p, client);
  // Connecting may take seconds (the graph starting): a thread of its own, the front's thread
  // goes on with the other pages. The page sends nothing but pongs before the graph's hello.
  relays_.fetch_add(1);
  std::thread([this, &p, client] {
    Relay(p, client);
    relays_.fetch_sub(1);
  }).detach();
}

int OnlineFront::TrialPort(Participant& p) const {
  std::string file;
  {
    MutexLock lock(mutex_);
    if (!p.running || p.port > 0) return p.running ? p.port : 0;
    file = p.port_file;
  }
  const int port = ReadPortFile(file);  // outside the lock: a file read
  MutexLock lock(mutex_);
  if (port > 0 && p.running && p.port_file == file) p.port = port;
  return p.running ? p.port : 0;
}

// Connects the page to the trial's graph (retrying while it starts), or, when the trial has
// ended meanwhile, tells the page what comes next.
void OnlineFront::Relay(Participant& p, web::ClientId client) {
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.wait_for_subject_s));
  web::WebServer* server = server_.load();
  while (true) {
    std::string token;
    {
      MutexLock lock(mutex_);
      if (!p.running || p.page != client) break;
      token = p.token;
    }
    // Only the port the graph itself bound and wrote (never one picked for it: another process
    // could take that first and be sent the participant's token).
    const int port = TrialPort(p);
    StatusOr<std::unique_ptr<web::WsClient>> up = Status::NotFound("the trial's graph has not written its port yet");
    if (port > 0) {
      web::WsClient::Callbacks cb;
      cb.on_text = [server, client](std::string_view text) { server->SendText(client, std::string(text)); };
      cb.on_close = [this, &p, client] { NextPhase(p, client, "the trial's page closed"); };
      up = web::WsClient::Connect("127.0.0.1", port, "/subject/ws?token=" + token, std::move(cb), std::chrono::seconds(2));
    }
    if (up.ok()) {
      std::shared_ptr<web::WsClient> relay(std::move(*up)), old;
      {
        MutexLock lock(mutex_);
        if (p.running && p.page == client) {
          old = std::exchange(p.upstream, relay);
          relay.reset();
        }
      }
      if (old) old->Close();  // never under mutex_: Close waits for its callbacks, which take it
      if (!relay) return;
      relay->Close();
      break;  // the page or the trial left meanwhile
    }
    // Nothing listens yet (the graph starting), or it is ending: again until the trial ends.
    if (Clock::now() > deadline) {
      std::cerr << "dyad study serve: " << p.id << ": cannot relay the page to its trial: " << up.status().ToString()
                << std::endl;
      break;
    }
    std::this_thread::sleep_for(kRelayRetry);
  }
  bool here = false, running = false;
  {
    MutexLock lock(mutex_);
    here = p.page == client;
    running = p.running;
  }
  if (here && !running) SendPhase(p, client);
  else if (here) NextPhase(p, client, "the trial is not reachable: retry");
}

void OnlineFront::NextPhase(Participant& p, web::ClientId client, const std::string& reason) {
  std::shared_ptr<web::WsClient> up;  // the page's relay goes with it (a stale one would fail the next page's frames)
  {
    MutexLock lock(mutex_);
    if (p.page != client) return;
    p.page = 0;  // before the close: the page's next socket may come before this one's OnClose
    p.session.PageClosed(Clock::now());
    up = std::move(p.upstream);
  }
  if (up) up->Close();  // after unlocking (also from the relay's own on_close: allowed there)
  Close(client, 1012, reason);
}

void OnlineFront::SendPhase(Participant& p, web::ClientId client) {
  bool broken = false;
  {
    MutexLock lock(mutex_);
    broken = p.failures >= kFailuresInARow;
  }
  const std::string frame = broken ? Refused(kBroken) : p.session.PageFrame();
  Send(client, frame);
  const bool refused = frame.find(R"("op":"refused")") != std::string::npos;
  if (!refused && frame.find(R"("op":"done")") == std::string::npos) {
    MutexLock lock(mutex_);
    if (p.page != client) return;
    p.view = frame.find(R"("op":"consent")") != std::string::npos ? "consent" : "waiting";
    p.answered = false;  // a new view: the page may answer it once
    return;
  }
  {
    MutexLock lock(mutex_);
    if (p.page != client) return;
    p.page = 0;
    p.session.PageFinished();  // nothing to come back for: not live
  }
  Close(client, refused ? 1008 : 1000, refused ? "refused" : "the session is complete");
}

// A pong to the front's ping: its round trip kept, not relayed.
bool OnlineFront::Pong(Participant& p, std::string_view text) {
  if (text.find("\"pong\"") == std::string_view::npos) return false;
  const Json j = Json::parse(text.begin(), text.end(), nullptr, false);
  if (!j.is_object() || j.value("op", "") != "pong") return false;
  MutexLock lock(mutex_);
  if (j.contains("id") && j["id"].is_number_integer() && j["id"].get<int>() == p.ping_id)
    p.rtt_ms = std::chrono::duration<double, std::milli>(Clock::now() - p.ping_sent).count();
  return true;
}

double OnlineFront::Pointer(Participant& p, std::string_view text) {
  const PointerScan scan = ScanPointer(text);
  if (scan.engaged) {
    MutexLock lock(mutex_);
    p.engaged = *scan.engaged;
  }
  return scan.wall_ms;
}

void OnlineFront::NotePointerDelay(double wall_ms, int64_t received_ns) {
  const double received_ms = static_cast<double>(received_ns) / 1e6;
  const double relayed_ms = static_cast<double>(WallNs()) / 1e6;
  MutexLock lock(delays_mutex_);
  if (to_worker_ms_.size() >= 1000000) return;  // a bound on memory (over 4 hours of one page)
  to_worker_ms_.push_back(received_ms - wall_ms);
  to_relayed_ms_.push_back(relayed_ms - received_ms);
}

bool OnlineFront::RelayAtOnce(web::ClientId client, std::string_view text, int64_t received_ns) {
  if (text.find("\"pong\"") != std::string_view::npos) return false;  // the front's own round trip, not relayed
  {
    MutexLock lock(events_mutex_);
    if (events_stopped_ || opening_.count(client) > 0 || in_flight_.count(client) > 0) return false;
  }
  Participant* p = nullptr;
  std::shared_ptr<web::WsClient> up;
  {
    MutexLock lock(mutex_);
    const auto it = clients_.find(client);
    if (it == clients_.end() || it->second->page != client || !it->second->upstream) return false;
    p = it->second;
    up = p->upstream;
    p->heard = Clock::now();
  }
  if (!up->SendText(text, kRelayWrite).ok()) return false;  // the front's thread tries it again, and ends the phase
  if (const double wall_ms = Pointer(*p, text); wall_ms >= 0) NotePointerDelay(wall_ms, received_ns);
  return true;
}

void OnlineFront::Text(web::ClientId client, std::string_view text, int64_t received_ns) {
  Participant* p = Of(client);
  if (p == nullptr) return;
  {
    MutexLock lock(mutex_);
    if (p->page == client) p->heard = Clock::now();
  }
  if (Pong(*p, text)) return;
  std::shared_ptr<web::WsClient> up;
  bool running = false;
  {
    MutexLock lock(mutex_);
    if (p->page != client) return;  // a page being closed
    up = p->upstream;
    running = p->running;
  }
  if (up) {
    if (Status st = up->SendText(text, kRelayWrite); !st.ok())
      NextPhase(*p, client, "the trial's graph does not take the page's frames");
    else if (const double wall_ms = Pointer(*p, text); wall_ms >= 0)  // only what reached the graph
      NotePointerDelay(wall_ms, received_ns);
    return;
  }
  if (!running) Answer(*p, client, text);
}

// The page's answers between trials.
void OnlineFront::Answer(Participant& p, web::ClientId client, std::string_view text) {
  const Json j = Json::parse(text.begin(), text.end(), nullptr, false);
  const std::string op = j.is_object() ? j.value("op", "") : "";
  {
    // One answer per view, to that view (consent to the consent page, ready to the waiting one):
    // anything else between trials is ignored, and a flood costs no log reads.
    MutexLock lock(mutex_);
    if (p.page != client || p.answered || op.empty() || op != (p.view == "waiting" ? "ready" : p.view)) return;
    p.answered = true;
  }
  if (op == "consent" && j.contains("agree") && j["agree"].is_boolean()) {
    if (p.session.phase() != OnlineSession::Phase::kConsent) return;  // an old view's answer
    const bool agree = j["agree"].get<bool>();
    if (Status st = p.session.Consent(agree); !st.ok())
      std::cerr << "dyad study serve: " << p.id << ": " << st.ToString() << std::endl;
    std::cout << p.id << (agree ? ": consent given on the consent page" : ": declined on the consent page") << std::endl;
    return SendPhase(p, client);
  }
  if (op != "ready" || p.session.phase() != OnlineSession::Phase::kWaiting) return;
  if (const std::string why = StartTrial(p); !why.empty()) {  // it cannot start: the page is told, and closed (1008)
    std::cout << p.id << ": a page refused: " << why << std::endl;
    Send(client, Refused(why));
    {
      MutexLock lock(mutex_);
      if (p.page != client) return;
      p.page = 0;
      p.session.PageFinished();
    }
    Close(client, 1008, "refused");
  }
}

std::string OnlineFront::StartTrial(Participant& p) {
  const std::optional<OnlineSession::Planned> next = p.session.Next();
  if (!next || closing_.load()) return "";
  {
    MutexLock lock(mutex_);
    if (p.failures >= kFailuresInARow) return kBroken;
  }
  const std::string token_file = (std::filesystem::path(study_.data) / p.id / (study_.subject_web + "-tokens")).string();
  auto token = ReadSubjectToken(token_file);
  if (!token.ok()) {
    std::cerr << "dyad study serve: " << p.id << ": trial " << next->trial.number
              << " cannot start: " << token.status().ToString() << std::endl;
    return kBroken;  // the page is told, not left with its Ready button pressed
  }
  // The graph binds a free loopback port itself and writes it into the participant's folder
  // (0700): the relay and the overview connect only to that port.
  const std::string port_file =
      (std::filesystem::path(study_.data) / p.id / (".trial-" + std::to_string(next->trial.number) + ".port")).string();
  AttemptRequest r;
  r.dyad = options_.dyad;
  r.participant = p.id;
  r.trial = next->trial;
  r.attempt = next->attempt;
  r.reason = next->reason;
  r.stop = &p.stop;
  r.own_signals = false;
  r.wait_for_subject_s = options_.wait_for_subject_s;
  r.run_log = std::filesystem::path(AttemptFile(r.trial, r.attempt)).replace_extension(".log").string();
  r.serve_sets = {study_.subject_web + ".address=127.0.0.1", study_.subject_web + ".port=0",
                  study_.subject_web + ".port_file=" + tools::YamlQuoted(port_file),
                  study_.subject_web + ".pause_without_subject=true"};
  r.incomplete_reason = [this, &p] {
    MutexLock lock(mutex_);
    return p.lost_reason;
  };
  std::lock_guard<std::mutex> worker(p.worker_mutex);
  if (closing_.load()) return "";
  if (p.worker.joinable()) p.worker.join();  // the last trial's thread, ended (running is false)
  web::ClientId page = 0;
  {
    MutexLock lock(mutex_);
    if (p.running || !p.ended.empty()) return "";
    if (domains_.range().size() > 0) {
      const std::optional<int> domain = domains_.Take();
      if (!domain) {  // a guard: a running trial keeps its session live, and serve gives max_sessions domains
        std::cerr << "dyad study serve: " << p.id << ": trial " << r.trial.number << " cannot start yet: every domain of "
                  << domains_.range().first << "-" << domains_.range().last << " has a trial's graph running" << std::endl;
        return kComeBack;
      }
      p.domain = *domain;
      r.serve_sets.push_back("domain_id=" + std::to_string(*domain));
    }
    p.running = true;
    p.trial = r.trial.number;
    p.attempt = r.attempt;
    p.file = AttemptFile(r.trial, r.attempt);
    p.engaged.reset();
    p.stop.store(false);
    p.lost_reason.clear();
    p.port = 0;
    p.port_file = port_file;
    p.token = *token;
    std::swap(page, p.page);
    p.session.PageClosed(Clock::now());  // it comes back at once, to the trial
  }
  std::error_code ec;
  std::filesystem::remove(port_file, ec);  // a stale one (a serve killed mid-trial): never read
  if (page != 0) Close(page, 1012, "the trial starts");
  p.worker = std::thread([this, &p, r] { RunTrial(p, r); });
  return "";
}

void OnlineFront::RunTrial(Participant& p, AttemptRequest r) {
  const size_t of = study_.TrialsOf(p.id).size();
  std::cout << p.id << ": trial " << r.trial.number << " of " << of << ": "
            << study_.Shown(study_.conditions[static_cast<size_t>(r.trial.condition)])
            << (r.attempt > 1 ? ", attempt " + std::to_string(r.attempt) + " (" + r.reason + ")" : "") << " -> "
            << AttemptFile(r.trial, r.attempt) << std::endl;
  auto a = RunAttempt(study_, r);
  const bool failed = !a.ok() || a->outcome == AttemptOutcome::kFailed;
  std::cout << p.id << ": trial " << r.trial.number << ": "
            << (a.ok() ? std::string(ToString(a->outcome)) + (a->incomplete.empty() ? "" : " (" + a->incomplete + ")") + ", " +
                             std::to_string(static_cast<int>(std::lround(a->seconds))) + " s"
                       : a.status().ToString())
            << std::endl;
  web::ClientId page = 0;
  std::shared_ptr<web::WsClient> up;
  {
    MutexLock lock(mutex_);
    p.running = false;
    if (p.domain >= 0) domains_.Give(p.domain);  // its graph has exited
    p.domain = -1;
    p.failures = failed ? p.failures + 1 : 0;
    if (p.failures == kFailuresInARow)
      std::cerr << "dyad study serve: " << p.id << ": trial " << r.trial.number << " failed " << kFailuresInARow
                << " times in a row (its graph's output is beside the recording): no more attempts for " << p.id
                << " until dyad study serve restarts" << std::endl;
    std::swap(page, p.page);
    up = std::move(p.upstream);
    if (page != 0) p.session.PageClosed(Clock::now());
    p.port = 0;
  }
  std::error_code ec;
  std::filesystem::remove(p.port_file, ec);  // p.port_file changes only in StartTrial, on this thread's join
  if (up) up->Close();
  if (page != 0) Close(page, 1012, "the trial ended");  // the page comes back at once and hears what is next
}

void OnlineFront::Closed(web::ClientId client) {
  std::shared_ptr<web::WsClient> up;
  {
    MutexLock lock(mutex_);
    const auto it = clients_.find(client);
    if (it == clients_.end()) return;
    Participant& p = *it->second;
    clients_.erase(it);
    if (p.page != client) return;  // closed by the front already (a phase change)
    p.page = 0;
    p.session.PageClosed(Clock::now());
    up = std::move(p.upstream);
  }
  if (up) up->Close();  // the graph sees its subject gone (and pauses)
}

void OnlineFront::Tick(Clock::time_point now) {
  std::vector<std::pair<web::ClientId, std::string>> pings;
  {
    MutexLock lock(mutex_);
    const auto reconnect = std::chrono::duration<double>(study_.online.reconnect_s);
    for (auto& [id, p] : participants_) {
      if (p->running && p->page == 0 && p->lost_reason.empty() && p->session.LostFor(now) > reconnect) {
        p->lost_reason = "the participant's connection was lost for more than " + Seconds(study_.online.reconnect_s) + " s";
        p->stop.store(true);
        std::cout << id << ": " << p->lost_reason << ": the trial is stopped" << std::endl;
      }
      if (!p->running && p->page == 0 && p->lock && !p->session.Live(now, false)) p->lock.reset();
      if (p->page != 0 && now - p->ping_sent >= options_.ping_interval) {
        p->ping_sent = now;
        pings.emplace_back(p->page, Json{{"op", "ping"}, {"id", ++p->ping_id}}.dump());
      }
    }
  }
  for (auto& [client, text] : pings) Send(client, std::move(text));
}

// The running trial's or the next one's place in the plan and condition, from the log.
static void PlanOf(const Study& s, OnlineSession& session, OnlineFront::SessionView& v) {
  const std::vector<Trial> trials = s.TrialsOf(v.participant);
  v.of = static_cast<int>(trials.size());
  if (v.trial == 0)
    if (const std::optional<OnlineSession::Planned> next = session.Next()) {
      v.trial = next->trial.number;
      v.attempt = next->attempt;
    }
  for (const Trial& t : trials)
    if (t.number == v.trial) v.shown = s.Shown(s.conditions[static_cast<size_t>(t.condition)]);
}

std::vector<OnlineFront::SessionView> OnlineFront::Snapshot(Clock::time_point now) const {
  std::vector<SessionView> out;
  {
    MutexLock lock(mutex_);
    for (const auto& [id, p] : participants_) {
      if (!p->session.Live(now, p->running) && p->ended.empty()) continue;
      SessionView v;
      v.participant = id;
      v.rtt_ms = p->rtt_ms;
      v.ended = p->ended;
      if (p->page == 0) v.gone_s = std::chrono::duration<double>(p->session.LostFor(now)).count();
      if (p->running) {
        v.phase = p->page == 0 ? "paused" : "trial";
        v.trial = p->trial;
        v.attempt = p->attempt;
        v.file = p->file;
        v.port = p->port;
        v.domain = p->domain;
        v.engaged = p->engaged;
      } else if (p->page == 0) {
        v.phase = "away";
      }
      out.push_back(std::move(v));
    }
  }
  // Between trials the phase and the next trial come from the log: read outside the lock.
  for (SessionView& v : out) {
    if (!v.file.empty() && v.port == 0) v.port = TrialPort(*participants_.at(v.participant));
    OnlineSession& session = participants_.at(v.participant)->session;
    if (v.file.empty()) {
      static constexpr const char* kNames[] = {"consent", "waiting", "done", "refused"};
      const OnlineSession::Phase ph = session.phase();
      const bool between = ph == OnlineSession::Phase::kConsent || ph == OnlineSession::Phase::kWaiting;
      if (!v.ended.empty()) v.phase = "ended";
      else if (v.phase != "away" || !between) v.phase = kNames[static_cast<int>(ph)];
    }
    PlanOf(study_, session, v);
  }
  return out;
}

Status OnlineFront::StopSession(const std::string& participant, const std::string& reason) {
  const auto it = participants_.find(participant);
  if (it == participants_.end()) return Status::NotFound("no participant '" + participant + "' in " + study_.file);
  if (reason.find_first_not_of(" \t\r\n") == std::string::npos)
    return Status::InvalidArgument("stopping " + participant + "'s session needs the reason (kept in their session log)");
  Participant& p = *it->second;
  {
    MutexLock lock(mutex_);
    if (!p.ended.empty()) return Status::FailedPrecondition(participant + "'s session has ended already: " + p.ended);
    p.ended = reason;
  }
  const Json line = {{"event", "session_ended"}, {"reason", reason}, {"how", "the experimenter's overview (dyad study serve)"}};
  if (Status st = AppendSessionEvent(study_, participant, line.dump()); !st.ok()) {
    MutexLock lock(mutex_);
    p.ended.clear();
    return st;
  }
  web::ClientId page = 0;
  bool running = false;
  {
    MutexLock lock(mutex_);
    running = p.running;
    if (running && p.lost_reason.empty()) p.lost_reason = "stopped by the experimenter: " + reason;
    if (running) p.stop.store(true);  // its end closes the page, which comes back to hear the session ended
    if (!running) {                   // nothing to come back for: the session's place is free at once
      std::swap(page, p.page);
      p.session.PageFinished();
    }
  }
  std::cout << participant << ": the session is ended by the experimenter: " << reason
            << (running ? " (its trial is stopped)" : "") << std::endl;
  if (page != 0) {
    Send(page, p.session.PageFrame());
    Close(page, 1008, "the session has ended");
  }
  return Status::OK();
}

Status OnlineFront::ResumeSession(const std::string& participant) {
  const auto it = participants_.find(participant);
  if (it == participants_.end()) return Status::NotFound("no participant '" + participant + "' in " + study_.file);
  if (ReadOnlineEvents(SessionLogPath(study_, participant)).ended.empty())
    return Status::FailedPrecondition(participant + "'s session has not been ended");
  const Json line = {{"event", "session_resumed"}, {"how", "the experimenter's overview (dyad study serve)"}};
  if (Status st = AppendSessionEvent(study_, participant, line.dump()); !st.ok()) return st;
  {
    MutexLock lock(mutex_);
    it->second->ended.clear();
  }
  std::cout << participant << ": the session is resumed by the experimenter (their link opens it again)" << std::endl;
  return Status::OK();
}

void OnlineFront::StopAll() {
  closing_.store(true);
  std::vector<web::ClientId> unopened;  // pages whose open was still queued: closed, nothing else
  {
    MutexLock lock(events_mutex_);
    events_stopped_ = true;
    unopened.assign(opening_.begin(), opening_.end());
    opening_.clear();
    events_.clear();
    queued_bytes_.clear();
    in_flight_.clear();
  }
  events_cv_.notify_all();
  for (web::ClientId client : unopened) Close(client, 1001, "the study's server is stopping");
  if (events_thread_.joinable()) events_thread_.join();  // the event it handles now (a page's phase, a trial's start)
  {
    MutexLock lock(delays_mutex_);
    LogPointerDelays(to_worker_ms_, to_relayed_ms_);
  }
  for (auto& [id, p] : participants_) p->stop.store(true);
  for (auto& [id, p] : participants_) {
    std::lock_guard<std::mutex> worker(p->worker_mutex);
    p->stop.store(true);  // a trial started before closing_ was seen
    if (p->worker.joinable()) p->worker.join();
  }
  std::vector<std::shared_ptr<web::WsClient>> ups;
  {
    MutexLock lock(mutex_);
    for (auto& [id, p] : participants_)
      if (p->upstream) ups.push_back(std::move(p->upstream));
  }
  for (auto& up : ups) up->Close();
  while (relays_.load() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));  // each ends within its connect timeout
}

}  // namespace dyad::study
