#include "study_page.hpp"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "dyad/private_file.hpp"
#include "study_session.hpp"
#include "subject_lobby.hpp"
#include "web_server.hpp"

namespace dyad::study {

extern const char* const kStudyPageHtml;  // study_page.html, embedded at configure time

namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

std::atomic<int> g_quit{0};  // lock-free: set by the handler, read by the main loop
extern "C" void OnQuitSignal(int) { g_quit.store(1); }

// A trial's graph waits this long for the subject's page to come back from the lobby (it retries
// every second) before its clock runs without it.
constexpr double kWaitForSubjectS = 15;
constexpr const char* kFirstPart = "Welcome. Please wait: the experimenter will start in a moment.";
constexpr const char* kNextPart = "Thank you. Please wait for the next part.";
constexpr const char* kSessionOver = "The session is over. Thank you for taking part!";

class StudyChannel final : public web::ClientHandler {
 public:
  StudyChannel(const Study& s, std::string participant, std::string dyad, SubjectLobby* lobby)
      : study_(s),
        participant_(std::move(participant)),
        dyad_(std::move(dyad)),
        trials_(s.TrialsOf(participant_)),
        lobby_(lobby) {}
  ~StudyChannel() override { Join(); }

  void SetServer(web::WebServer* server) { server_.store(server); }
  void Close() { closing_.store(true); }  // no trial starts any more
  bool running() const { return running_.load(); }
  bool done() const { return done_.load(); }
  void StopTrial() { stop_.store(true); }
  void Join() {
    if (worker_.joinable()) worker_.join();
  }

  // Every page gets the state (from the session log, so it is what the terminal would say).
  void Broadcast() {
    web::WebServer* server = server_.load();
    if (server == nullptr) return;
    const std::string text = StateJson().dump();
    for (web::ClientId c : server->clients()) server->SendText(c, text);
  }

  void OnOpen(web::ClientId client, web::Role) override {
    if (web::WebServer* server = server_.load()) server->SendText(client, StateJson().dump());
  }
  Status OnBinary(web::ClientId, std::span<const uint8_t>) override { return Status::InvalidArgument("text frames only"); }
  void OnClose(web::ClientId) override {}

  Status OnText(web::ClientId client, std::string_view text) override {
    const Json j = Json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("op") || !j["op"].is_string())
      return Status::InvalidArgument("not a JSON object with an \"op\"");
    const std::string op = j["op"];
    std::string refused;
    if (op == "consent") refused = Consent();
    else if (op == "stop") stop_.store(true);
    else if (op == "note") {
      if (!j.contains("text") || !j["text"].is_string()) return Status::InvalidArgument("note: needs a string \"text\"");
      if (Status st = AddNote(study_, participant_, j["text"].get<std::string>()); !st.ok()) refused = st.ToString();
    } else if (op == "withdraw") {
      if (!j.contains("delete") || !j["delete"].is_boolean()) return Status::InvalidArgument("withdraw: needs a boolean \"delete\"");
      refused = Withdraw(j["delete"].get<bool>());
    }
    else if (op == "start") {
      if (!j.contains("trial") || !j["trial"].is_number_integer()) return Status::InvalidArgument("start: needs an integer \"trial\"");
      refused =
          Start(j["trial"].get<int>(), j.contains("reason") && j["reason"].is_string() ? j["reason"].get<std::string>() : "",
                j.contains("anyway") && j["anyway"].is_boolean() && j["anyway"].get<bool>());
    } else {
      return Status::InvalidArgument("unknown op '" + op + "'");
    }
    if (!refused.empty())
      if (web::WebServer* server = server_.load()) server->SendText(client, Json{{"op", "error"}, {"message", refused}}.dump());
    Broadcast();
    return Status::OK();
  }

 private:
  std::string Consent() {
    const Session session = ReadSession(study_, participant_);
    if (session.consent) return "";
    if (session.withdrawn)
      return participant_ + " withdrew consent: a new consent is marked only with dyad study run --consent";
    if (Status s = MarkConsent(study_, participant_, "marked on the study page"); !s.ok()) return s.ToString();
    std::cout << "consent marked for " << participant_ << " (on the study page)" << std::endl;
    return "";
  }

  // The runner holds the participant's lock; no trial may run while their files go.
  std::string Withdraw(bool delete_data) {
    if (running_.load()) return "trial " + std::to_string(current_trial_) + " is running: stop it first";
    auto deleted = WithdrawConsent(study_, participant_, delete_data, "on the study page");
    if (!deleted.ok()) return deleted.status().ToString();
    std::cout << participant_ << " withdrew consent (on the study page)"
              << (delete_data ? ": " + std::to_string(*deleted) + " files deleted" : std::string()) << std::endl;
    return "";
  }

  // Why trial `k` may not start now, or "" once it has. Not before the subject's page is open
  // (there is a lobby), unless `anyway`.
  std::string Start(int k, const std::string& reason, bool anyway) {
    if (closing_.load()) return "the study page is closing";
    if (running_.load()) return "trial " + std::to_string(current_trial_) + " is running: stop it first";
    const Session session = ReadSession(study_, participant_);
    if (session.withdrawn) return participant_ + " withdrew consent: nothing is recorded for them";
    if (study_.consent_required && !session.consent) return "consent is required and not marked: nothing was recorded";
    if (std::string why = WhyNotStart(session, trials_, k, reason); !why.empty()) return why;
    const bool no_page = lobby_ != nullptr && lobby_->pages() == 0;
    if (no_page && !anyway)
      return "the subject's page is not open: open the subject's link on the participant's screen (it waits there), "
             "or Start anyway (the session log says so)";
    const Attempt* last = session.Last(k);
    AttemptRequest r;
    r.dyad = dyad_;
    r.participant = participant_;
    r.trial = trials_[static_cast<size_t>(k - 1)];
    r.attempt = last ? last->attempt + 1 : 1;
    while (std::filesystem::exists(AttemptFile(r.trial, r.attempt))) ++r.attempt;
    r.reason = reason;
    r.stop = &stop_;
    if (lobby_ != nullptr) {
      r.subject_port = lobby_->port();
      r.wait_for_subject_s = no_page ? 0 : kWaitForSubjectS;
      r.start_anyway = no_page;
    }
    // A blind experimenter must not read the graph's output (its parameters): a file beside the recording.
    if (study_.blind) r.run_log = std::filesystem::path(AttemptFile(r.trial, r.attempt)).replace_extension(".log").string();
    Join();
    stop_.store(false);
    running_.store(true);
    current_trial_ = k;
    current_attempt_ = r.attempt;
    started_ = Clock::now();
    std::cout << "trial " << k << " of " << trials_.size() << ": " << study_.Shown(study_.conditions[static_cast<size_t>(r.trial.condition)])
              << (r.attempt > 1 ? ", attempt " + std::to_string(r.attempt) : "") << " -> " << AttemptFile(r.trial, r.attempt) << std::endl;
    worker_ = std::thread([this, r] {
      if (lobby_ != nullptr) lobby_->Close();  // the trial's graph takes the port; the page follows it
      auto a = RunAttempt(study_, r);
      ReopenLobby();
      std::cout << "  trial " << r.trial.number << ": "
                << (a.ok() ? std::string(ToString(a->outcome)) + " (" +
                                 std::to_string(static_cast<int>(std::lround(a->seconds))) + " s)"
                           : a.status().ToString())
                << std::endl;
      {
        std::lock_guard<std::mutex> lock(error_mutex_);
        last_error_ = a.ok() ? "" : a.status().ToString();
      }
      running_.store(false);
      Broadcast();
    });
    return "";
  }

  // After a trial: the page comes back to wait, told whether more is to come.
  void ReopenLobby() {
    if (lobby_ == nullptr) return;
    if (Status st = lobby_->Open(); !st.ok()) {
      std::cerr << "dyad study run: " << st.ToString() << "\n";
      return;
    }
    const Session session = ReadSession(study_, participant_);
    bool done = true;
    for (const Trial& t : trials_) done = done && session.Complete(t.number);
    lobby_->SetMessage(done ? kSessionOver : kNextPart);
  }

  Json StateJson() {
    const Session session = ReadSession(study_, participant_);
    Json trials = Json::array();
    bool done = true;
    for (const Trial& t : trials_) {
      int attempts = 0;
      for (const Attempt& a : session.attempts) attempts += a.trial == t.number;
      const Attempt* last = session.Last(t.number);
      std::string status = "to do";
      const bool now_running = running_.load() && current_trial_.load() == t.number;
      if (session.Complete(t.number)) status = "complete";
      else if (now_running) status = "running";
      else if (last && last->outcome == AttemptOutcome::kIncomplete && last->incomplete.rfind("no subject", 0) == 0)
        status = "no subject: repeat?";
      else if (last) status = last->outcome == AttemptOutcome::kUnended ? "interrupted" : std::string(ToString(last->outcome));
      done = done && session.Complete(t.number);
      trials.push_back({{"number", t.number},
                        {"shown", study_.Shown(study_.conditions[static_cast<size_t>(t.condition)])},
                        {"file", std::filesystem::path(t.file).filename().string()},
                        {"status", status},
                        {"attempts", attempts}});
    }
    Json notes = Json::array();
    for (const Note& n : session.notes) notes.push_back({{"time", n.time}, {"trial", n.trial}, {"text", n.text}});
    Json running = nullptr;
    if (running_.load())
      running = {{"trial", current_trial_.load()},
                 {"attempt", current_attempt_.load()},
                 {"elapsed_s", std::chrono::duration<double>(Clock::now() - started_.load()).count()}};
    std::string error;
    {
      std::lock_guard<std::mutex> lock(error_mutex_);
      error = last_error_;
    }
    done_.store(done);
    Json subject = nullptr;  // the session's subject's link, and whether its page waits there
    if (lobby_ != nullptr) subject = {{"links", lobby_->Links()}, {"pages", lobby_->pages()}};
    return {{"op", "state"},
            {"study", study_.name},
            {"participant", participant_},
            {"blind", study_.blind},
            {"consent_required", study_.consent_required},
            {"consent", session.consent},
            {"withdrawn", session.withdrawn},
            {"notes", notes},
            {"duration_s", study_.duration_s},
            {"after_trial", study_.self_reports == SelfReports::kAfterTrial},
            {"trials", trials},
            {"running", running},
            {"done", done},
            {"subject", subject},
            {"error", error.empty() ? Json(nullptr) : Json(error)}};
  }

  const Study& study_;
  const std::string participant_, dyad_;
  const std::vector<Trial> trials_;
  SubjectLobby* const lobby_;  // null: the graph has no subject's page to serve between trials
  std::atomic<web::WebServer*> server_{nullptr};
  std::atomic<bool> running_{false}, stop_{false}, closing_{false}, done_{false};
  std::atomic<int> current_trial_{0}, current_attempt_{0};
  std::atomic<Clock::time_point> started_{Clock::time_point{}};
  std::mutex error_mutex_;
  std::string last_error_;  // why the last attempt could not run (guarded by error_mutex_)
  std::thread worker_;
};

}  // namespace

namespace {

std::uintmax_t LogSize(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t n = std::filesystem::file_size(path, ec);
  return ec ? 0 : n;
}

// The session's subject's page (subject_lobby.hpp), when the graph has one: its token from the
// participant's token file (made now when missing), on the web component's address and port.
Status OpenLobby(const Study& study, const std::string& participant, const PageOptions& o, std::unique_ptr<SubjectLobby>* out) {
  if (study.subject_web.empty()) return Status::OK();
  const std::filesystem::path dir = std::filesystem::path(study.data) / participant;
  if (Status st = CreatePrivateDirectories(dir.string()); !st.ok()) return st;
  auto token = SubjectToken((dir / (study.subject_web + "-tokens")).string());
  if (!token.ok()) return token.status();
  auto lobby =
      std::make_unique<SubjectLobby>(study.subject_address, o.subject_port >= 0 ? o.subject_port : study.subject_port, *token);
  if (Status st = lobby->Open(); !st.ok()) return st;
  lobby->SetMessage(kFirstPart);
  *out = std::move(lobby);
  return Status::OK();
}

}  // namespace

tools::ExitCode RunStudyPage(const Study& study, const std::string& participant, const PageOptions& o) {
  // Before anything can start a trial: a trial's own handlers restore these when it ends.
  struct sigaction sa {}, old_int {}, old_term {};
  sa.sa_handler = OnQuitSignal;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  std::unique_ptr<SubjectLobby> lobby;
  if (Status st = OpenLobby(study, participant, o, &lobby); !st.ok()) {
    std::cerr << "dyad study run: " << st.ToString() << "\n";
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    return tools::ExitCode::kFailure;
  }
  StudyChannel channel(study, participant, o.dyad, lobby.get());
  web::WebServer::Options so;
  so.address = o.address;
  so.port = o.port;
  const std::string token = web::RandomToken();
  so.tokens = {{web::Role::kExperimenter, token}};
  so.pages["/study"] = web::WebServer::Page{"text/html; charset=utf-8", kStudyPageHtml, {web::Role::kExperimenter}, ""};
  so.endpoints.push_back(web::WebServer::Endpoint{"/study/ws", {}, &channel, {web::Role::kExperimenter}, false});
  auto server = web::WebServer::Start(so);
  if (!server.ok()) {
    std::cerr << "dyad study run: the study page: " << server.status().ToString() << "\n";
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    return tools::ExitCode::kFailure;
  }
  channel.SetServer(server->get());
  if (!o.port_file.empty()) std::ofstream(o.port_file) << (*server)->port() << "\n";
  for (const std::string& host : web::UrlHosts(o.address))
    std::cout << "study page: http://" << host << ":" << (*server)->port() << "/study?token=" << token << std::endl;
  if (lobby && !study.blind)
    for (const std::string& link : lobby->Links()) std::cout << "subject's page: " << link << std::endl;
  // A signal during a trial stops the trial (RunAttempt's own handlers); between trials it ends
  // here, and so does the session once every trial is complete (the pages are told first).
  // A note written from a terminal (dyad study note) shows within a second: the log grew.
  const std::string log = SessionLogPath(study, participant);
  std::uintmax_t log_size = LogSize(log);
  int lobby_pages = 0;
  channel.Broadcast();
  for (auto next = Clock::now(); !(g_quit.load() && !channel.running()); std::this_thread::sleep_for(std::chrono::milliseconds(50))) {
    if (g_quit.load() && channel.running()) channel.StopTrial();
    if (Clock::now() < next) continue;
    next = Clock::now() + std::chrono::milliseconds(500);
    const std::uintmax_t size = LogSize(log);
    const int pages = lobby ? lobby->pages() : 0;  // the subject's page came or went
    if (channel.running() || size != log_size || pages != lobby_pages) channel.Broadcast();
    log_size = size;
    lobby_pages = pages;
    if (!channel.running() && channel.done()) {
      std::cout << "session complete" << std::endl;
      // The subject's page comes back from the last trial's graph (it retries every second) to
      // hear that the session is over; the study page's last state leaves.
      for (int i = 0; i < 30 && lobby && lobby->pages() == 0 && !g_quit.load(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      break;
    }
  }
  channel.Close();
  channel.SetServer(nullptr);
  server->reset();  // no request can come any more
  channel.Join();
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  bool done = true;
  const Session session = ReadSession(study, participant);
  for (const Trial& t : study.TrialsOf(participant)) done = done && session.Complete(t.number);
  std::cout << "study page closed: " << (done ? "every trial complete" : "trials remain") << std::endl;
  return done ? tools::ExitCode::kOk : tools::ExitCode::kFailure;  // as the terminal's session while trials remain
}

}  // namespace dyad::study
