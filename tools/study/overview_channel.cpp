#include "overview_channel.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <vector>

#include <nlohmann/json.hpp>

#include "dyad/private_file.hpp"
#include "study_links.hpp"
#include "study_session.hpp"
#include "ws_client.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
constexpr size_t kMaxText = 4096;  // a note's or a reason's bytes

Json OrNull(double v, bool known) { return known ? Json(v) : Json(nullptr); }

}  // namespace

StatusOr<std::string> ServeExperimenterToken(const Study& s) {
  const std::string file = (fs::path(s.data) / "serve-tokens").string();
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(file, ec))) {
    if (Status d = CreatePrivateDirectories(s.data); !d.ok()) return d;
    const std::string token = web::RandomToken();
    Status w = WritePrivateFile(file, "experimenter " + token + "\n", CreateMode::kNew);
    if (w.ok()) return token;
    if (w.code() != Status::Code::kFailedPrecondition) return w;
    // Another instance on the same folder made it this instant: its token, once it is written.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return ReadRoleToken(file, "experimenter", "the experimenter's overview token");
}

std::optional<StepStats> ParseStats(std::string_view frame) {
  if (frame.find("\"stats\"") == std::string_view::npos) return std::nullopt;
  const Json j = Json::parse(frame.begin(), frame.end(), nullptr, false);
  if (!j.is_object() || j.value("op", "") != "stats" || !j.contains("rows") || !j["rows"].is_array()) return std::nullopt;
  StepStats out;
  bool any = false;  // a row with its p99 (none before the components' first stats)
  for (const Json& row : j["rows"]) {
    if (!row.is_object()) continue;
    if (row.contains("misses") && row["misses"].is_number()) out.misses += row["misses"].get<long>();
    if (row.contains("p99_ms") && row["p99_ms"].is_number() && (!any || row["p99_ms"].get<double>() > out.p99_ms)) {
      any = true;
      out.p99_ms = row["p99_ms"].get<double>();
      out.component = row.contains("component") && row["component"].is_string() ? row["component"].get<std::string>() : "";
    }
  }
  if (!any) return std::nullopt;
  return out;
}

// A running trial's stats link: its graph's /experimenter/ws.
struct OverviewChannel::Upstream {
  std::string key;  // participant#attempt:port
  std::mutex mutex;
  std::optional<StepStats> stats;  // under mutex (the client's thread writes it)
  std::atomic<bool> closed{false};
  std::unique_ptr<web::WsClient> client;  // last: closed first, before what its callbacks use
};

OverviewChannel::OverviewChannel(const Study& s, OnlineFront* front, int max_sessions)
    : study_(s), front_(front), max_sessions_(max_sessions) {}

OverviewChannel::~OverviewChannel() { Stop(); }

void OverviewChannel::Start() {
  thread_ = std::thread([this] { Loop(); });
}

void OverviewChannel::Stop() {
  stopping_.store(true);
  if (thread_.joinable()) thread_.join();
  std::map<std::string, std::shared_ptr<Upstream>> gone;
  {
    MutexLock lock(mutex_);
    gone.swap(stats_);
  }
  gone.clear();  // each client closed, outside the lock
}

void OverviewChannel::Loop() {
  while (!stopping_.load()) {
    bool watched = false;
    {
      MutexLock lock(mutex_);
      watched = !pages_.empty();
    }
    if (watched) {  // nobody watching: no log read, no stats link (a page that opens gets them within a second)
      const std::vector<OnlineFront::SessionView> sessions = front_->Snapshot(Clock::now());
      UpdateStats(sessions);
      Broadcast(StateOf(sessions));
    }
    for (int i = 0; i < 20 && !stopping_.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// One stats link per running trial: made when its graph listens, dropped when the trial ends.
void OverviewChannel::UpdateStats(const std::vector<OnlineFront::SessionView>& sessions) {
  std::map<std::string, std::string> wanted;  // participant -> key
  std::map<std::string, int> ports;
  for (const auto& v : sessions)
    if (!v.file.empty() && v.port > 0) {
      wanted[v.participant] = v.participant + "#" + std::to_string(v.attempt) + ":" + std::to_string(v.port);
      ports[v.participant] = v.port;
    }
  std::vector<std::shared_ptr<Upstream>> gone;
  std::vector<std::pair<std::string, std::string>> connect;  // (participant, key)
  {
    MutexLock lock(mutex_);
    for (auto it = stats_.begin(); it != stats_.end();) {
      const auto w = wanted.find(it->first);
      if (w == wanted.end() || w->second != it->second->key || it->second->closed.load()) {
        gone.push_back(std::move(it->second));
        it = stats_.erase(it);
      } else {
        ++it;
      }
    }
    for (const auto& [participant, key] : wanted)
      if (!stats_.count(participant)) connect.emplace_back(participant, key);
  }
  gone.clear();
  for (const auto& [participant, key] : connect) {
    const std::string tokens = (fs::path(study_.data) / participant / (study_.subject_web + "-tokens")).string();
    auto token = ReadRoleToken(tokens, "experimenter", "a participant's tokens");
    if (!token.ok()) continue;  // the front refuses such a participant's trial already
    auto up = std::make_shared<Upstream>();
    up->key = key;
    Upstream* raw = up.get();
    web::WsClient::Callbacks cb;
    cb.on_text = [raw](std::string_view text) {
      if (auto s = ParseStats(text)) {
        std::lock_guard<std::mutex> lock(raw->mutex);
        raw->stats = *s;
      }
    };
    cb.on_close = [raw] { raw->closed.store(true); };
    auto client = web::WsClient::Connect("127.0.0.1", ports[participant], "/experimenter/ws?token=" + *token, std::move(cb),
                                         std::chrono::milliseconds(1000));
    if (!client.ok()) continue;  // the graph not listening yet: again in a second
    up->client = std::move(*client);
    MutexLock lock(mutex_);
    stats_[participant] = std::move(up);
  }
}

std::string OverviewChannel::StateOf(const std::vector<OnlineFront::SessionView>& sessions) {
  Json rows = Json::array();
  for (const auto& v : sessions) {
    std::error_code ec;
    const auto bytes = v.file.empty() ? 0 : fs::file_size(v.file, ec);
    std::optional<StepStats> stats;
    {
      MutexLock lock(mutex_);
      const auto it = stats_.find(v.participant);
      if (it != stats_.end()) {
        std::lock_guard<std::mutex> up(it->second->mutex);
        stats = it->second->stats;
      }
    }
    rows.push_back(Json{{"participant", v.participant},
                        {"phase", v.phase},
                        {"gone_s", v.gone_s},
                        {"trial", v.trial},
                        {"of", v.of},
                        {"attempt", v.attempt},
                        {"shown", v.shown},
                        {"file", v.file},
                        {"domain", v.domain >= 0 ? Json(v.domain) : Json(nullptr)},  // `dyad echo --domain` reaches its graph
                        {"recording_bytes", v.file.empty() || ec ? Json(nullptr) : Json(bytes)},
                        {"engaged", v.phase == "paused" ? Json(false)
                                    : v.engaged         ? Json(*v.engaged)
                                                        : Json(nullptr)},
                        {"rtt_ms", OrNull(v.rtt_ms, v.rtt_ms >= 0)},
                        {"step_p99_ms", OrNull(stats ? stats->p99_ms : 0, stats.has_value())},
                        {"step_component", stats ? stats->component : ""},
                        {"misses", stats ? Json(stats->misses) : Json(nullptr)},
                        {"ended", v.ended}});
  }
  return Json{{"op", "state"},
              {"study", study_.name},
              {"blind", study_.blind},
              {"participants", study_.participants.size()},
              {"max_sessions", max_sessions_},
              {"reconnect_s", study_.online.reconnect_s},
              {"sessions", rows}}
      .dump();
}

std::string OverviewChannel::State(Clock::time_point now) { return StateOf(front_->Snapshot(now)); }

void OverviewChannel::Send(web::ClientId client, const std::string& text) {
  if (web::WebServer* server = server_.load()) server->SendText(client, text);
}

void OverviewChannel::Broadcast(const std::string& text) {
  std::set<web::ClientId> pages;
  {
    MutexLock lock(mutex_);
    pages = pages_;
  }
  for (web::ClientId page : pages) Send(page, text);
}

void OverviewChannel::OnOpen(web::ClientId client, web::Role role) {
  if (role != web::Role::kExperimenter) {
    if (web::WebServer* server = server_.load()) server->Close(client, 1008, "the experimenter's only");
    return;
  }
  {
    MutexLock lock(mutex_);
    pages_.insert(client);
  }
  Send(client, State(Clock::now()));
}

void OverviewChannel::OnClose(web::ClientId client) {
  MutexLock lock(mutex_);
  pages_.erase(client);
}

// Carries out the page's request; `request` and `participant` say what it was.
Status OverviewChannel::Request(std::string_view text, std::string* request, std::string* participant) {
  const Json j = Json::parse(text.begin(), text.end(), nullptr, false);
  if (!j.is_object() || !j.contains("op") || !j["op"].is_string() || !j.contains("participant") || !j["participant"].is_string())
    return Status::InvalidArgument("a request is {\"op\":\"note\"|\"stop\"|\"resume\",\"participant\":...}");
  *request = j["op"];
  *participant = j["participant"];
  const std::string field = *request == "note" ? "text" : *request == "stop" ? "reason" : "";
  if (!field.empty() && (!j.contains(field) || !j[field].is_string() || j[field].get<std::string>().size() > kMaxText))
    return Status::InvalidArgument(*request + ": \"" + field + "\" is a text of at most 4 KiB");
  const std::vector<std::string>& all = study_.participants;
  if (std::find(all.begin(), all.end(), *participant) == all.end())
    return Status::NotFound("no participant '" + *participant + "' in " + study_.file);
  if (*request == "note") return AddNote(study_, *participant, j["text"].get<std::string>());
  if (*request == "stop") return front_->StopSession(*participant, j["reason"].get<std::string>());
  if (*request == "resume") return front_->ResumeSession(*participant);
  return Status::InvalidArgument("unknown request '" + *request + "' (note, stop, resume)");
}

Status OverviewChannel::OnText(web::ClientId client, std::string_view text) {
  {
    MutexLock lock(mutex_);
    if (!pages_.count(client)) return Status::OK();
  }
  std::string request, participant;
  const Status st = Request(text, &request, &participant);
  if (!st.ok()) {
    Send(client, Json{{"op", "error"}, {"message", st.message()}}.dump());
    return Status::OK();
  }
  if (request == "note") std::cout << participant << ": a note from the experimenter's overview" << std::endl;
  Send(client, Json{{"op", "done"}, {"request", request}, {"participant", participant}}.dump());
  Broadcast(State(Clock::now()));
  return Status::OK();
}

}  // namespace dyad::study
