#include "web_component.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <dyad/decode_sample.hpp>
#include <dyad/encode_sample.hpp>
#include <dyad/graph.hpp>
#include <dyad/on_demand_subscription.hpp>
#include <dyad/private_file.hpp>
#include <dyad/pvrnn/dataset.hpp>
#include <dyad/run_stopping.hpp>
#include <dyad/topic_select.hpp>

#include "pages.hpp"
#include "web_human.hpp"

namespace dyad::web {
namespace {

// Where each role's token comes from, in order: its param, its environment variable, the
// token_file's line for it, else a new one.
struct RoleSource {
  Role role;
  const char* param;
  const char* env;
};
constexpr RoleSource kRoleSources[] = {{Role::kExperimenter, "token", "DYAD_WEB_TOKEN"},
                                       {Role::kSubject, "subject_token", "DYAD_WEB_SUBJECT_TOKEN"},
                                       {Role::kViewer, "viewer_token", "DYAD_WEB_VIEWER_TOKEN"}};

// A usable token: 16..256 printable characters that stand in a URL's query as they are.
Status CheckToken(const std::string& token, const std::string& where) {
  if (token.size() < 16 || token.size() > 256 ||
      !std::all_of(token.begin(), token.end(), [](char c) { return c > ' ' && c < 127 && c != '&' && c != '#' && c != '+' && c != '%'; }))
    return Status::InvalidArgument(where + ": a token is 16..256 printable characters without spaces, '&', '#', '+' or '%'");
  return Status::OK();
}

// The tokens kept in `path` (params.token_file): a regular file, not a link, readable by its
// owner only, with one line "ROLE TOKEN" for each of experimenter, subject and viewer.
StatusOr<std::map<Role, std::string>> ReadTokenFile(const std::string& path) {
  const std::string key = "params.token_file = '" + path + "'";
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return Status::NotFound(key + ": missing");
  if (S_ISLNK(st.st_mode) || !S_ISREG(st.st_mode)) return Status::InvalidArgument(key + ": not a regular file (a link is refused)");
  if ((st.st_mode & 077) != 0) return Status::InvalidArgument(key + ": readable by others: chmod 600 it");
  std::ifstream in(path);
  std::map<Role, std::string> tokens;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string where = key + " line " + std::to_string(n);
    const size_t space = line.find(' ');
    std::optional<Role> role;
    for (const auto& r : kRoleSources)
      if (space != std::string::npos && line.compare(0, space, RoleName(r.role)) == 0) role = r.role;
    if (!role) return Status::InvalidArgument(where + ": expected 'experimenter TOKEN', 'subject TOKEN' or 'viewer TOKEN'");
    const std::string token = line.substr(space + 1);
    if (Status s = CheckToken(token, where); !s.ok()) return s;
    tokens[*role] = token;
  }
  for (const auto& r : kRoleSources)
    if (!tokens.count(r.role))
      return Status::InvalidArgument(key + ": no line for the " + RoleName(r.role) +
                                     "'s token (a file from before per-role tokens: delete it and a new one is made)");
  return tokens;
}

// Every (process, component) of the graph as run, placed as the runtime places them.
std::set<std::pair<std::string, std::string>> GraphsComponents(const Context& ctx) {
  std::vector<Diagnostic> diags;  // the runtime parsed this text before: none
  const Graph g = ParseGraph(ctx.graph_yaml(), ctx.graph_folder() + "/graph.yaml", {}, &diags);
  std::set<std::pair<std::string, std::string>> out;
  for (const auto& c : g.components) out.insert({g.ProcessOf(c), c.name});
  return out;
}

// {"op":"learner", ...}: the learner's status for the experimenter's page (NaN: null).
nlohmann::json LearnerJson(const msg::LearnerStatus& m) {
  auto number = [](double v) -> nlohmann::json { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json segments = nlohmann::json::array();
  for (size_t i = 0; i < m.segment_start_s().size() && i < m.segment_duration_s().size() && i < m.segment_laps().size(); ++i)
    segments.push_back({{"start_s", m.segment_start_s()[i]}, {"duration_s", m.segment_duration_s()[i]}, {"laps", m.segment_laps()[i]}});
  return {{"op", "learner"}, {"component", m.component_name()}, {"state", m.state()}, {"run", m.run()}, {"segments", segments},
          {"chosen", m.chosen()}, {"epoch", m.epoch()}, {"epochs", m.epochs()}, {"loss", number(m.loss())},
          {"folder", m.folder()}, {"model", m.model()}, {"message", m.message()}, {"elapsed_s", number(m.elapsed_s())},
          {"since_demonstration_s", number(m.since_demonstration_s())}};
}

}  // namespace

// A sample of dyad/processes or dyad/health into the experimenter's list of run events (one not
// from a dyad runtime of this version is not shown).
template <class Message>
void AddEvent(RunEvents& events, const SerializedSample& sample) {
  Message m;
  if (!DecodeSample(sample.cdr, &m).ok()) return;
  events.Add(m, std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
}

namespace {
// A sample of dyad/params into the experimenter's list of answers.
void AddAnswer(ParamAnswers& answers, const SerializedSample& sample) {
  msg::ParamChange m;
  if (!DecodeSample(sample.cdr, &m).ok()) return;
  answers.Add(m, std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
}
}  // namespace

void WebComponent::Describe(ComponentSpec& spec) {
  spec.Summary("Embedded web server with a live Foxglove WebSocket bridge over the graph's topics.");
  spec.Param("address", "127.0.0.1").Doc("address to bind; anything but loopback needs tls_certificate (or plain_http)");
  spec.Param("port", 8765).Range(0, 65535).Doc("TCP port; 0 picks a free one (see port_file)");
  spec.Param("topics", std::vector<std::string>{}).Doc("topics to advertise, by name or regular expression (empty: all)");
  spec.Param("writable", std::vector<std::string>{}).Doc("topics Foxglove clients may publish on (empty: none)");
  spec.Param("token", "").Secret().Doc("the experimenter's token (every page, notes, publishing on writable topics); empty: "
                                       "$DYAD_WEB_TOKEN, token_file's, else generated and printed");
  spec.Param("subject_token", "").Secret().Doc("the subject's token (the subject's page, steering); empty: "
                                               "$DYAD_WEB_SUBJECT_TOKEN, token_file's, else generated and printed");
  spec.Param("viewer_token", "").Secret().Doc("the viewer's token (watch only: pages without steering or notes, Foxglove "
                                              "read-only); empty: $DYAD_WEB_VIEWER_TOKEN, token_file's, else generated");
  spec.Param("token_file", "").Path().Doc("a 0600 file of 'ROLE TOKEN' lines: read when it exists, else created with new "
                                          "tokens (bookmarked pages keep working across runs); its tokens are not printed");
  spec.Param("tls_certificate", "").Path().Doc("PEM file (0600): private key, then certificate chain; the server then speaks "
                                               "HTTPS and WSS only");
  spec.Param("plain_http", false).Doc("allow a non-loopback address without TLS (tokens and data cross the network in clear)");
  spec.Param("allowed_origins", std::vector<std::string>{}).Doc("browser origins allowed besides localhost ('*': any)");
  spec.Param("max_clients", 8).Range(1, 64).Doc("WebSocket clients at once");
  spec.Param("client_buffer_kb", 4096).Range(16, 1 << 20).Doc("per-client send buffer; past it the busiest channel's oldest samples are dropped");
  spec.Param("max_frame_kb", 1024).Range(1, 1 << 20).Doc("a larger frame from a client closes it");
  spec.Param("port_file", "").Path().Doc("write the bound port to this file (tests, scripts)");
  spec.Param("engage_key", "Space").Doc("subject's page: the key (KeyboardEvent.code) that engages while held, besides the mouse button");
  spec.Param("half_width", 50.0).Min(1e-6).Doc("subject's page: the workspace drawn is [-half_width, half_width]^2 (the study's 50)");
  spec.Param("show_primitives", false).Doc("subject's page: draw the data set's primitives as a faint watermark");
  spec.Param("dataset", "").Path().Doc("subject's page: NRL data set folder of the primitives (the watermark, the question's thumbnails)");
  spec.Param("self_reports", "after_event").OneOf({"after_event", "after_trial", "off"}).Doc(
      "subject's page: with `self_report` bound, ask \"What were you drawing?\" (the data set's primitives as thumbnails, "
      "and \"something else\") after each release, or after the trial about each of its holds in turn (see `ask`)");
  spec.Param("self_report_min_hold_s", 1.0).Min(0).Unit("s").Doc("subject's page: ask only about a hold at least this long");
  spec.Param("ask", false).Live().Doc(
      "after_trial: setting it true ends the trial: steering stops, the subject's page asks about each hold (its stroke, the "
      "pointer's path while held, as the picture), and once all are answered (or self_report_timeout_s passed) the run ends by itself");
  spec.Param("ask_after_s", 0.0).Min(0).Unit("s").Doc(
      "after_trial: ask by itself this long after the run's start (`dyad study run` sets it to the trial's duration; 0: only "
      "when `ask` is set)");
  spec.Param("self_report_timeout_s", 120.0).Range(1, 86400).Unit("s").Doc(
      "after_trial: the run ends this long after the questions began, answered or not");
  spec.Param("task_target", int64_t{-1}).Range(-1, 1e6).Live().Doc(
      "subject's page: the data set's primitive to draw, drawn boldly over the workspace (-1: none; needs params.dataset)");
  spec.Param("task_message", "").Live().Doc("subject's page: a message above the workspace (empty: none)");
  spec.Param("task_countdown_s", 0.0).Range(0, 3600).Unit("s").Live().Doc(
      "subject's page: setting it starts a countdown of that many seconds, then \"go\" (the same value again restarts it)");
  spec.Param("practice", false).Live().Doc("subject's page says \"practice\"; dyad analyze leaves the events meanwhile out (the `task` output recorded)");
  spec.Param("task_time_s", 0.0)
      .Range(0, 86400)
      .Unit("s")
      .Doc(
          "subject's page: the time left of a trial this long from the run's first step (0: not shown; dyad study run sets the "
          "study's duration)");
  spec.Param("wait_for_subject_s", 0.0)
      .Range(0, 3600)
      .Unit("s")
      .Doc(
          "the run's clock starts only once a page steers (the subject's, reconnecting), waiting at most this long (a stop "
          "request ends the wait); 0: no wait (dyad study run sets it for each trial of a session)");
  spec.Param("pause_without_subject", false)
      .Doc(
          "while no page steers (the subject's page is gone, e.g. a participant's lost connection) the trial pauses: `pointer` "
          "carries the pause marker (x = y = NaN) on which web_human stops publishing, so the mixer holds the robot; `notes` "
          "marks it (author web, \"paused: ...\" / \"resumed: ...\"). Not during the questions after the trial (dyad study "
          "serve sets it)");
  spec.Input<msg::CartesianState>("robot").Optional().Doc("robot state shown on the subject's page");
  spec.Output<msg::SubjectTask>("task").Optional().Doc(
      "what the subject's page shows besides the robot (target, message, countdown, practice): at the start and each change; "
      "bind to subject/task, which dyad analyze reads");
  spec.Input<msg::Intention>("intention").Optional().Doc("experimenter's page: the deliberator's N-ELBO");
  spec.Input<msg::IntentionLabel>("labels").Optional().Doc("experimenter's page: the observer's P(C_t) and labels");
  spec.Input<msg::RecordingStatus>("recording").Optional().Doc(
      "experimenter's page: a recorder's status (its `status` output): the file, samples, size and elapsed time, or its failure");
  spec.Input<msg::LearnerStatus>("learner").Optional().Doc(
      "experimenter's page: a learner's status; the page then offers \"learn from this session\" (its demonstrations, "
      "the training's loss, the swap)");
  spec.Output<msg::Annotation>("notes").Doc("experimenter's notes (record this topic to align them with the run)");
  spec.Output<msg::HumanInput>("pointer").Doc(
      "the steering page's pointer, at the browser's event rate (to web_human); x = y = NaN: paused (pause_without_subject)");
  spec.Output<msg::SelfReport>("self_report").Optional().Doc(
      "the subject's answers: choice, response time (from the release; after the trial from its question), the hold's start "
      "and end (runtime clock)");
}

Status WebComponent::Configure(Context& ctx) {
  ctx_ = &ctx;
  const Params& p = ctx.params();
  options_.address = p.String("address");
  options_.port = static_cast<int>(p.Int("port"));
  options_.allowed_origins = p.StringList("allowed_origins");
  options_.max_clients = static_cast<int>(p.Int("max_clients"));
  options_.client_buffer_bytes = static_cast<size_t>(p.Int("client_buffer_kb")) << 10;
  options_.max_frame_bytes = static_cast<size_t>(p.Int("max_frame_kb")) << 10;

  if (Status s = ChooseTokens(p); !s.ok()) return s;
  if (Status s = ChooseTls(p); !s.ok()) return s;
  port_file_ = p.String("port_file");
  pause_without_subject_ = p.Bool("pause_without_subject");
  if (Status s = ConfigureBridge(ctx, p); !s.ok()) return s;
  if (Status s = ConfigureSubject(ctx, p); !s.ok()) return s;
  if (Status s = ConfigureTask(ctx, p); !s.ok()) return s;
  if (Status s = ConfigureExperimenter(ctx); !s.ok()) return s;
  ConfigurePages();
  return Status::OK();
}

// The Foxglove bridge: the advertised topics (read while a client subscribes) and the writable ones.
Status WebComponent::ConfigureBridge(Context& ctx, const Params& p) {
  std::vector<std::string> names;
  for (const auto& t : ctx.graph_topics()) names.push_back(t.name);
  auto chosen = SelectTopics(p.StringList("topics"), names, "params.topics");
  if (!chosen.ok()) return chosen.status();
  std::vector<foxglove::Channel> channels;
  for (const auto& name : *chosen)
    for (const auto& t : ctx.graph_topics())
      if (t.name == name)
        channels.push_back(foxglove::Channel{static_cast<uint32_t>(channels.size() + 1), t.name, t.type->name, t.type->idl});

  std::map<std::string, SerializedWriter*> writers;
  const auto writable = p.StringList("writable");
  writable_ = writable;
  for (size_t i = 0; i < writable.size(); ++i) {
    const TopicInfo* info = nullptr;
    for (const auto& t : ctx.graph_topics())
      if (t.name == writable[i]) info = &t;
    if (info == nullptr)
      return Status::InvalidArgument("params.writable[" + std::to_string(i) + "] = '" + writable[i] + "': not a topic of the graph");
    auto w = ctx.AdvertiseSerialized(info->name, *info->type);
    if (!w.ok()) return w.status().WithContext("params.writable[" + std::to_string(i) + "]");
    writers[info->name] = *w;
  }

  bridge_ = std::make_unique<FoxgloveBridge>("dyad/" + ctx.graph_name(), channels, std::move(writers));
  // Read only while a client subscribes (the bridge starts and stops them).
  FoxgloveBridge* bridge = bridge_.get();
  for (const auto& c : channels) {
    const uint32_t id = c.id;
    auto sub = SubscribeSerializedOnDemand(ctx, c.topic, [bridge, id](const SerializedSample& sample) { bridge->OnSample(id, sample); });
    if (!sub.ok()) return sub.status().WithContext("params.topics: '" + c.topic + "'");
    bridge_->SetSubscription(id, *sub);
  }
  return Status::OK();
}

// The subject's page: the robot's state to it, its pointer to `pointer`.
Status WebComponent::ConfigureSubject(Context& ctx, const Params& p) {
  SubjectChannel::Options so;
  so.engage_key = p.String("engage_key");
  so.half_width = p.Double("half_width");
  reports_ = &ctx.output<msg::SelfReport>("self_report");
  so.watermark = p.Bool("show_primitives");
  so.ask = reports_->bound() && p.String("self_reports") == "after_event";
  after_trial_ = reports_->bound() && p.String("self_reports") == "after_trial";
  if (!reports_->bound() && p.String("self_reports") == "after_trial")
    ctx.log().Warn("params.self_reports: after_trial, but the self_report output is not bound: the page asks nothing and "
                   "does not end the run");
  ask_after_ns_ = static_cast<int64_t>(std::llround(p.Double("ask_after_s") * 1e9));
  question_timeout_ns_ = static_cast<int64_t>(std::llround(p.Double("self_report_timeout_s") * 1e9));
  ctx.CheckLiveParam("ask", [this](const ParamValue& v) {
    if (std::get<bool>(v) && !after_trial_)
      return Status::FailedPrecondition("only a page with self_reports: after_trial and its self_report output bound asks after the trial");
    return Status::OK();
  });
  so.ask_after_hold_s = p.Double("self_report_min_hold_s");
  min_hold_ns_ = static_cast<int64_t>(std::llround(so.ask_after_hold_s * 1e9));
  if (so.watermark || so.ask || after_trial_ || p.Int("task_target") >= 0) {
    const std::string why = so.watermark              ? "params.show_primitives"
                            : so.ask || after_trial_ ? "params.self_reports (the question's thumbnails)"
                                         : "params.task_target";
    if (p.String("dataset").empty()) return Status::InvalidArgument(why + ": needs params.dataset (an NRL data set folder)");
  }
  if (!p.String("dataset").empty()) {  // a target may be shown later too
    auto data = pvrnn::LoadNrlDataset(p.String("dataset"));
    if (!data.ok()) return data.status().WithContext("params.dataset");
    for (const auto& seq : data->sequences) {
      if (seq.rows() < 2) return Status::InvalidArgument("params.dataset: primitives need 2 DOFs (x, y), got " + std::to_string(seq.rows()));
      std::vector<std::array<double, 2>> pts;
      for (Eigen::Index t = 0; t < seq.cols(); ++t) pts.push_back({seq(0, t), seq(1, t)});
      so.primitives.push_back(std::move(pts));
    }
    so.names = primitive_names_ = data->names;
  }
  primitives_ = static_cast<int>(so.primitives.size());
  robot_ = &ctx.input<msg::CartesianState>("robot");
  pointer_ = &ctx.output<msg::HumanInput>("pointer");
  // Both sinks are serialised by SubjectChannel (component.hpp: one Output's Publish calls must
  // not overlap), so the hold they share needs no lock of its own.
  subject_ = std::make_unique<SubjectChannel>(
      so,
      [this](double x, double y, bool engaged) {
        std::lock_guard<std::mutex> lock(pointer_mutex_);
        pointed_since_pause_ = true;
        const int64_t now = ctx_->clock().now_ns();
        if (engaged && !holding_) hold_start_ns_ = now;
        if (!engaged && holding_) hold_end_ns_ = now, answerable_ = true;
        if (after_trial_) MarkHold(x, y, engaged && !holding_, !engaged && holding_, now);
        holding_ = engaged;
        pointer_sample_.x(x);
        pointer_sample_.y(y);
        pointer_sample_.engaged(engaged);
        if (Status s = pointer_->Publish(pointer_sample_); !s.ok()) ctx_->log().Warn("pointer: " + s.ToString());
      },
      [this](int choice, int segment) { return PublishSelfReport(choice, segment); });
  return Status::OK();
}

// The experimenter's task for the person: live params, checked here, sent to the subject's pages
// and published on `task` by Step().
Status WebComponent::ConfigureTask(Context& ctx, const Params& p) {
  task_out_ = &ctx.output<msg::SubjectTask>("task");
  auto check_target = [this](int64_t target) -> Status {
    if (target < 0) return Status::OK();
    if (primitives_ == 0) return Status::InvalidArgument("no data set to show a target from (params.dataset)");
    if (target >= primitives_)
      return Status::InvalidArgument("the data set has " + std::to_string(primitives_) + " primitives (0.." + std::to_string(primitives_ - 1) +
                                     "), got " + std::to_string(target));
    return Status::OK();
  };
  if (Status s = check_target(p.Int("task_target")); !s.ok()) return Status::InvalidArgument("params.task_target: " + s.message());
  ctx.CheckLiveParam("task_target", [check_target](const ParamValue& v) { return check_target(std::get<int64_t>(v)); });
  ctx.PrepareLiveParam(
      "task_countdown_s", [](const ParamValue&) { return Status::OK(); }, [this](const ParamValue&) { countdown_asked_ = true; });
  countdown_asked_ = p.Double("task_countdown_s") > 0;
  return Status::OK();
}

// At the first step and whenever the task changed: to the subject's pages and on `task`.
void WebComponent::StepTask() {
  const Params& p = ctx_->params();
  SubjectChannel::Task t = task_;
  t.target = static_cast<int>(p.Int("task_target"));
  t.message = p.String("task_message");
  t.practice = p.Bool("practice");
  const bool countdown = countdown_asked_;
  if (countdown) {
    t.countdown_s = p.Double("task_countdown_s");
    t.countdown_start = std::chrono::steady_clock::now();
    countdown_asked_ = false;
  }
  if (!task_sent_ && p.Double("task_time_s") > 0) {  // the first step: the trial's clock
    t.time_s = p.Double("task_time_s");
    t.time_start = std::chrono::steady_clock::now();
  }
  if (task_sent_ && !countdown && t.target == task_.target && t.message == task_.message && t.practice == task_.practice) return;
  task_ = t;
  task_sent_ = true;
  subject_->SetTask(t);
  if (!task_out_->bound()) return;
  msg::SubjectTask m;
  m.target(t.target);
  m.message(t.message);
  m.countdown_s(countdown ? t.countdown_s : 0);
  m.practice(t.practice);
  // Like the pointer: a lost sample is said, the pages and the run go on.
  if (Status s = task_out_->Publish(m); !s.ok()) ctx_->log().Warn("task: not published: " + s.ToString());
}

namespace {
// Appends `at` to a hold's path unless it is where the path already is (a keepalive, a robot at
// rest). A long hold's path is halved (every other point) when it reaches kMaxPathPoints: its
// memory stays bounded, its shape kept.
constexpr size_t kMaxPathPoints = 8192;
void Extend(SubjectChannel::Trace& path, const std::array<double, 2>& at) {
  if (!path.empty() && path.back() == at) return;
  if (path.size() >= kMaxPathPoints) {
    for (size_t i = 0; 2 * i < path.size(); ++i) path[i] = path[2 * i];
    path.resize((path.size() + 1) / 2);
  }
  path.push_back(at);
}
}  // namespace

// A pointer sample (after_trial): whether a hold starts or ends, and where the pointer is (the
// hold's stroke: the person's own drawing, asked about after the trial). A hold shorter than
// self_report_min_hold_s is no event and is forgotten.
void WebComponent::MarkHold(double x, double y, bool starts, bool ends, int64_t now) {
  std::lock_guard<std::mutex> lock(holds_mutex_);
  if (asking_) return;  // the trial is over: nothing more to ask about
  if (starts) {
    holds_.push_back(Hold{now, 0, {{x, y}}, {}});
    return;
  }
  if (holds_.empty() || holds_.back().end_ns != 0) return;  // no hold under way
  Extend(holds_.back().stroke, {x, y});
  if (!ends) return;
  holds_.back().end_ns = now;
  if (now - holds_.back().start_ns < min_hold_ns_) holds_.pop_back();
}

// The answer: after an event (segment -1), about the last hold, once (a second click, or an
// answer while holding again, is ignored); after the trial, about hold `segment`.
Status WebComponent::PublishSelfReport(int choice, int segment) {
  const int64_t now = ctx_->clock().now_ns();
  msg::SelfReport r;
  r.choice(choice);
  if (segment >= 0) {
    std::lock_guard<std::mutex> lock(holds_mutex_);
    if (!asking_ || segment >= static_cast<int>(asked_.size())) return Status::OK();
    const Hold& h = asked_[static_cast<size_t>(segment)];
    r.response_s(static_cast<double>(now - question_shown_ns_) * 1e-9);
    r.segment_start_ns(h.start_ns);
    r.segment_end_ns(h.end_ns);
    question_shown_ns_ = now;  // the next question is shown now
  } else {
    // The server's own checks, whatever a page sends: a finished hold, long enough to be asked about.
    if (!answerable_ || holding_ || hold_end_ns_ - hold_start_ns_ < min_hold_ns_) return Status::OK();
    answerable_ = false;
    r.response_s(static_cast<double>(now - hold_end_ns_) * 1e-9);
    r.segment_start_ns(hold_start_ns_);
    r.segment_end_ns(hold_end_ns_);
  }
  Status published = reports_->Publish(r);
  if (!published.ok()) ctx_->log().Warn("self_report: the subject's answer was lost: " + published.ToString());
  if (segment >= 0) {
    if (!published.ok()) ++lost_;
    ++answered_;  // the page goes on to the next question either way
  }
  return Status::OK();
}

namespace {
// At most `n` points of `trace`, evenly taken, the last one kept (a page draws it in a thumbnail).
SubjectChannel::Trace Thin(const SubjectChannel::Trace& trace, size_t n) {
  if (trace.size() <= n) return trace;
  SubjectChannel::Trace out;
  for (size_t i = 0; i < n; ++i) out.push_back(trace[i * (trace.size() - 1) / (n - 1)]);
  return out;
}
}  // namespace

// Each step of self_reports: after_trial: the trace of the hold under way; then, once asked (the
// `ask` param, or ask_after_s into the run), the questions; the run's end once they are answered
// or timed out.
void WebComponent::StepAfterTrial(int64_t now, bool robot_moved) {
  if (first_step_ns_ < 0) first_step_ns_ = now;
  if (!asking_) {
    {
      std::lock_guard<std::mutex> lock(holds_mutex_);
      // The robot's path during the hold under way, drawn faintly beside the person's stroke.
      const msg::CartesianState* r = robot_->latest();
      if (r != nullptr && !holds_.empty() && holds_.back().end_ns == 0 && (robot_moved || holds_.back().robot.empty()))
        Extend(holds_.back().robot, {r->x(), r->y()});
    }
    const bool due = ctx_->params().Bool("ask") || (ask_after_ns_ > 0 && now - first_step_ns_ >= ask_after_ns_);
    if (due) StartQuestions(now);
    return;
  }
  if (stop_requested_) return;
  const int of = static_cast<int>(asked_.size());
  const bool timed_out = now - question_start_ns_ >= question_timeout_ns_;
  if (answered_ >= of && all_answered_ns_ < 0) all_answered_ns_ = now;
  // Half a second after the last answer: the page's "thank you" leaves before the server goes.
  if (timed_out || (all_answered_ns_ >= 0 && now - all_answered_ns_ >= 500'000'000)) {
    stop_requested_ = true;
    std::string what = std::to_string(answered_.load()) + " of " + std::to_string(of) + " holds answered";
    if (lost_ > 0) what += ", " + std::to_string(lost_.load()) + " of the answers lost (see above)";
    if (answered_ < of) ctx_->log().Warn("self_report: the questions timed out (params.self_report_timeout_s): " + what);
    ctx_->RequestStop("the trial is over and its questions ended (" + what + ")");
  }
}

nlohmann::json WebComponent::QuestionsJson() {
  if (!after_trial_) return nullptr;
  std::lock_guard<std::mutex> lock(holds_mutex_);
  // Before the questions: the holds ended so far (one under way, or too short, is not one yet).
  const auto ended = std::count_if(holds_.begin(), holds_.end(), [](const Hold& h) { return h.end_ns != 0; });
  return {{"asked", asking_}, {"answered", answered_.load()}, {"of", asking_ ? static_cast<int64_t>(asked_.size()) : ended}};
}

// Ends the steering, then asks the subject's page about each hold of the trial. The steering
// ends first: the hold under way ends with the release the channel publishes (MarkHold, at its
// time), and no hold starts after it.
void WebComponent::StartQuestions(int64_t now) {
  subject_->EndSteering();
  std::vector<SubjectChannel::Question> questions;
  {
    std::lock_guard<std::mutex> lock(holds_mutex_);
    asking_ = true;
    if (!holds_.empty() && holds_.back().end_ns == 0) {
      holds_.back().end_ns = now;
      if (now - holds_.back().start_ns < min_hold_ns_) holds_.pop_back();
    }
    asked_ = std::move(holds_);
    for (const Hold& h : asked_) questions.push_back({Thin(h.stroke, 300), Thin(h.robot, 300)});
    question_start_ns_ = question_shown_ns_ = now;
  }
  ctx_->log().Info("self_report: the trial is over; asking the subject about its " + std::to_string(questions.size()) + " holds");
  subject_->AskAfterTrial(std::move(questions));
}

// The experimenter's page: series, notes, live parameters, stats, run events.
Status WebComponent::ConfigureExperimenter(Context& ctx) {
  intention_ = &ctx.input<msg::Intention>("intention");
  labels_ = &ctx.input<msg::IntentionLabel>("labels");
  learner_ = &ctx.input<msg::LearnerStatus>("learner");
  recording_ = &ctx.input<msg::RecordingStatus>("recording");
  notes_ = &ctx.output<msg::Annotation>("notes");
  // Requests are written as the page asks (a generic writer: the runtime's topic, not a port to bind).
  auto requests = ctx.AdvertiseSerialized("dyad/param_requests", TypeInfoOf<msg::ParamChange>());
  if (!requests.ok()) return requests.status().WithContext("live parameters");
  param_requests_ = *requests;
  experimenter_ = std::make_unique<ExperimenterChannel>(
      [this](const std::string& text) {
        std::lock_guard<std::mutex> lock(notes_mutex_);
        note_.author("experimenter");
        note_.text(text);
        // Serialised by ExperimenterChannel.
        if (Status s = notes_->Publish(note_); !s.ok()) ctx_->log().Warn("notes: experimenter's note lost: " + s.ToString());
      },
      [this](const ParamRequest& request) { return PublishParamRequest(request); });
  stats_ = std::make_shared<StatsTable>(GraphsComponents(ctx));
  events_ = std::make_shared<RunEvents>();
  answers_ = std::make_shared<ParamAnswers>(ctx.graph_name());
  for (const auto& t : ctx.graph_topics()) {
    Status s;
    if (t.name == "dyad/stats") {
      std::shared_ptr<StatsTable> table = stats_;
      s = ctx.SubscribeSerialized(t.name, [table](const SerializedSample& sample) { table->Add(sample.cdr); });
    } else if (t.name == "dyad/processes") {
      s = ctx.SubscribeSerialized(t.name, [events = events_](const SerializedSample& sample) { AddEvent<msg::ProcessState>(*events, sample); });
    } else if (t.name == "dyad/health") {
      s = ctx.SubscribeSerialized(t.name, [events = events_](const SerializedSample& sample) { AddEvent<msg::HealthEvent>(*events, sample); });
    } else if (t.name == "dyad/params") {
      s = ctx.SubscribeSerialized(t.name, [answers = answers_](const SerializedSample& sample) { AddAnswer(*answers, sample); });
    }
    if (!s.ok()) return s;
  }
  return Status::OK();
}

void WebComponent::ConfigurePages() {
  const std::set<Role> everyone = {Role::kViewer, Role::kSubject, Role::kExperimenter};
  const std::set<Role> watchers = {Role::kViewer, Role::kExperimenter};  // not the subject: no stats, no notes
  const std::string html = "text/html; charset=utf-8";
  options_.pages["/"] = WebServer::Page{html, kIndexHtml, everyone, ""};
  options_.pages["/subject"] = WebServer::Page{html, kSubjectHtml, everyone, ""};
  options_.pages["/experimenter"] = WebServer::Page{html, kExperimenterHtml, watchers, ""};
  options_.endpoints = {
      WebServer::Endpoint{"/", {foxglove::kSubprotocol, foxglove::kSubprotocolSdk}, bridge_.get(), watchers},
      // The subject steers by the robot state on this page: no batching delay.
      WebServer::Endpoint{"/subject/ws", {}, subject_.get(), everyone, /*viewers=*/false},
      WebServer::Endpoint{"/experimenter/ws", {}, experimenter_.get(), watchers},
  };
}

// On a web server thread, one at a time (ExperimenterChannel serialises its sinks).
StatusOr<std::string> WebComponent::PublishParamRequest(const ParamRequest& r) {
  const uint64_t n = param_request_.header().sequence_number() + 1;
  const int64_t now = ctx_->clock().now_ns();
  param_request_.header().source(ctx_->name());
  param_request_.header().sequence_number(n);
  param_request_.header().stamp_ns(now);
  param_request_.graph_name(ctx_->graph_name());
  param_request_.component_name(r.component);
  param_request_.param_name(r.param);
  param_request_.op(r.set ? "set" : "get");
  param_request_.value(r.set ? r.value : "");
  param_request_.who("experimenter page");
  // Unique across runs and processes: this process, its clock, its count.
  param_request_.request_id("experimenter page/" + std::to_string(getpid()) + "/" + std::to_string(now) + "/" + std::to_string(n));
  const std::vector<uint8_t> cdr = EncodeSample(param_request_);
  if (cdr.empty()) return Status::Internal("the request did not encode");
  if (Status s = param_requests_->Write(cdr, now); !s.ok()) {
    ctx_->log().Warn("live parameters: " + r.component + "." + r.param + ": request not published: " + s.ToString());
    return s;
  }
  ctx_->log().Info("live parameters: asked " + r.component + "." + r.param + (r.set ? " = " + r.value : " (get)") +
                   " (experimenter page, " + param_request_.request_id() + ")");
  return param_request_.request_id();
}

Status WebComponent::Activate() {
  auto s = WebServer::Start(options_);
  if (!s.ok()) return s.status().WithContext(options_.tls_certificate.empty() ? "params.address/port" : "params.address/port/tls_certificate");
  server_ = std::move(s.value());
  bridge_->SetServer(server_.get());
  subject_->SetServer(server_.get());
  experimenter_->SetServer(server_.get());
  if (!token_file_text_.empty()) {
    if (Status s = WritePrivateFile(token_file_, token_file_text_, CreateMode::kNew); !s.ok())
      return s.WithContext("params.token_file");
  }
  LogUrls();
  if (!port_file_.empty()) {
    std::ofstream f(port_file_);
    f << server_->port() << "\n";
    if (!f) return Status::IOError("params.port_file = '" + port_file_ + "': cannot write");
  }
  WaitForSubject(ctx_->params().Double("wait_for_subject_s"));
  return Status::OK();
}

// In Activate, so the run's clock (which starts once every component is active) and the
// trial's first step wait for the subject's page: a page already open (a study's session-long
// link) reconnects within a second of the server starting. A run asked to stop meanwhile (Ctrl-C,
// SIGTERM: a study's trial stopped) ends the wait at once.
void WebComponent::WaitForSubject(double seconds) {
  if (seconds <= 0) return;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!subject_->steered() && std::chrono::steady_clock::now() < until && !RunStopping(*ctx_))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (subject_->steered()) ctx_->log().Info("the subject's page is there: the run starts");
  else if (RunStopping(*ctx_)) ctx_->log().Info("the run is stopping: no more waiting for the subject's page");
  else
    ctx_->log().Warn("no subject's page steers after " + std::to_string(std::lround(seconds)) +
                     " s (params.wait_for_subject_s): the run starts without one");
}

// params.pause_without_subject: when no page steers, the pause marker on `pointer` (web_human
// then publishes a release and nothing more: the mixer's human input goes stale and it holds)
// and a mark in the recording; when a page steers again, a released sample where the pointer was
// (unless the page's own came first: web_human publishes again) and the resume mark. After the
// trial (the questions) nothing steers on purpose: no pause then.
void WebComponent::StepPause(int64_t now) {
  if (!pause_without_subject_ || (after_trial_ && asking_)) return;
  const bool there = subject_->steered();
  const std::string text = there ? "resumed: the subject's page is back" : "paused: the subject's page is gone";
  {
    std::lock_guard<std::mutex> lock(pointer_mutex_);
    if (there != paused_) return;
    paused_ = !there;
    // The mark first: what web_human does on the sample below comes after it in the recording.
    Mark(text);
    msg::HumanInput sample = pointer_sample_;
    sample.engaged(false);
    if (paused_) {
      sample.x(std::numeric_limits<double>::quiet_NaN());
      sample.y(std::numeric_limits<double>::quiet_NaN());
      pointed_since_pause_ = false;
    }
    if (paused_ || !pointed_since_pause_) {
      if (Status s = pointer_->Publish(sample); !s.ok()) ctx_->log().Warn("pointer: the pause's sample: " + s.ToString());
    }
  }
  if (!there) ++pauses_, pause_start_ns_ = now;
  else paused_ns_ += now - pause_start_ns_;
  ctx_->log().Info(text + " (params.pause_without_subject)");
}

// A note by "web" on `notes` (recorded beside the experimenter's).
void WebComponent::Mark(const std::string& text) {
  std::lock_guard<std::mutex> lock(notes_mutex_);
  msg::Annotation mark;
  mark.author("web");
  mark.text(text);
  if (Status s = notes_->Publish(mark); !s.ok()) ctx_->log().Warn("notes: the mark '" + text + "' was lost: " + s.ToString());
}

Status WebComponent::Step(const StepInfo& info) {
  StepTask();
  StepPause(info.now_ns);
  if (after_trial_) StepAfterTrial(ctx_->clock().now_ns(), robot_->new_count() > 0);
  if (robot_->new_count() > 0) {
    const msg::CartesianState* r = robot_->latest();
    subject_->BroadcastState(r->x(), r->y());
  }
  if (intention_->new_count() > 0 || labels_->new_count() > 0) {
    nlohmann::json j{{"op", "series"}, {"t", info.now_ns * 1e-9}, {"nelbo", nullptr}, {"congruence", nullptr},
                     {"human", nullptr}, {"robot", nullptr}};
    if (const msg::Intention* i = intention_->latest()) j["nelbo"] = i->nelbo();
    if (const msg::IntentionLabel* l = labels_->latest()) {
      if (std::isfinite(l->congruence())) j["congruence"] = l->congruence();
      auto argmax = [](const std::vector<double>& p) -> nlohmann::json {
        if (p.empty()) return nullptr;
        return static_cast<int>(std::max_element(p.begin(), p.end()) - p.begin());
      };
      j["human"] = argmax(l->human());
      j["robot"] = argmax(l->robot());
    }
    experimenter_->Broadcast(1, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  if (info.now_ns - last_stats_ns_ >= 1'000'000'000) {
    last_stats_ns_ = info.now_ns;
    experimenter_->Broadcast(2, stats_->Json());
    if (std::string events = events_->Json(); !events.empty()) experimenter_->Broadcast(3, std::move(events));
    if (std::string answers = answers_->Json(); !answers.empty()) experimenter_->Broadcast(4, std::move(answers));
    // Whether the participant's page is there and holding (the experimenter cannot see it).
    experimenter_->Broadcast(5, nlohmann::json{{"op", "subject"},
                                               {"pages", subject_->pages()},
                                               {"engaged", holding_.load()},
                                               {"after_trial", after_trial_},
                                               {"questions", QuestionsJson()},
                                               {"component", ctx_->name()},
                                               {"primitives", primitives_},
                                               {"names", primitive_names_},
                                               {"task", {{"target", task_.target}, {"message", task_.message}, {"practice", task_.practice}}}}
                                    .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  if (learner_->new_count() > 0)
    experimenter_->Broadcast(6, LearnerJson(*learner_->latest()).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  if (recording_->new_count() > 0) {
    const msg::RecordingStatus& r = *recording_->latest();
    experimenter_->Broadcast(7, nlohmann::json{{"op", "recording"}, {"component", r.component_name()}, {"file", r.file()},
                                               {"samples", r.samples()}, {"bytes", r.bytes()}, {"elapsed_s", r.elapsed_s()},
                                               {"error", r.error()}}
                                    .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  bridge_->ReportDrops();
  return Status::OK();
}

Status WebComponent::Deactivate() {
  // Samples may still arrive until the runtime closes the subscriptions: the bridge keeps its
  // server pointer valid until the server is gone, so stop routing first.
  bridge_->SetServer(nullptr);
  subject_->SetServer(nullptr);
  experimenter_->SetServer(nullptr);
  server_.reset();
  ctx_->log().Info(std::to_string(bridge_->samples_sent()) + " samples sent to clients");
  if (pauses_ > 0) {
    const int64_t paused_ns = paused_ns_ + (paused_ ? ctx_->clock().now_ns() - pause_start_ns_ : 0);
    char text[160];
    std::snprintf(text, sizeof text, "paused %d times without the subject's page, %.1f s in all%s", pauses_,
                  static_cast<double>(paused_ns) * 1e-9, paused_ ? " (still paused at the end)" : "");
    ctx_->log().Info(text);
  }
  LogPointerDelays();
  return Status::OK();
}

// Each role's token: its param, else its environment variable, else the token_file's, else a
// new one. What the printed URLs show instead of a token says where it is; only a token dyad
// drew and keeps nowhere else is printed (else nobody could use it).
Status WebComponent::ChooseTokens(const Params& p) {
  options_.tokens.clear();
  shown_.clear();
  token_file_ = p.String("token_file");
  token_file_text_.clear();
  std::map<Role, std::string> kept;
  bool make_file = false;
  if (!token_file_.empty()) {
    auto read = ReadTokenFile(token_file_);
    if (read.ok()) kept = std::move(read.value());
    else if (read.status().code() == Status::Code::kNotFound) make_file = true;  // created at Activate
    else return read.status();
  }
  for (const auto& r : kRoleSources) {
    std::string& token = options_.tokens[r.role];
    std::string& shown = shown_[r.role];
    if (token = p.String(r.param); !token.empty()) {
      shown = std::string("<params.") + r.param + ">";
    } else if (const char* env = std::getenv(r.env); env != nullptr && *env != '\0') {
      token = env;
      shown = std::string("<$") + r.env + ">";
    } else if (kept.count(r.role)) {
      token = kept[r.role];
      shown = std::string("<the ") + RoleName(r.role) + "'s token in " + token_file_ + ">";
    } else {
      token = RandomToken();
      shown = make_file ? std::string("<the ") + RoleName(r.role) + "'s token in " + token_file_ + ">" : token;
    }
    const std::string where = shown.rfind("<params.", 0) == 0 ? std::string("params.") + r.param : shown;
    if (Status s = CheckToken(token, where); !s.ok()) return s;
    if (make_file) token_file_text_ += std::string(RoleName(r.role)) + " " + token + "\n";
  }
  for (const auto& a : kRoleSources)
    for (const auto& b : kRoleSources)
      if (a.role < b.role && options_.tokens[a.role] == options_.tokens[b.role])
        return Status::InvalidArgument(std::string("params.") + a.param + " and params." + b.param +
                                       ": the same token for two roles (a token says its role)");
  return Status::OK();
}

// TLS off loopback: a certificate file that is private, or plain HTTP asked for by name.
Status WebComponent::ChooseTls(const Params& p) {
  options_.tls_certificate = p.String("tls_certificate");
  if (options_.tls_certificate.empty()) {
    if (IsLoopback(options_.address) || p.Bool("plain_http")) return Status::OK();
    return Status::InvalidArgument("params.address = '" + options_.address +
                                   "': off loopback the tokens and the subject's data would cross the network in clear: give "
                                   "params.tls_certificate (dyad security init ... --web-host HOST makes one), or set "
                                   "params.plain_http: true on a network you trust");
  }
  // A missing file is reported when the server starts: `dyad security init --web-host`
  // configures this graph before it makes the file.
  struct stat st {};
  const std::string key = "params.tls_certificate = '" + options_.tls_certificate + "'";
  if (lstat(options_.tls_certificate.c_str(), &st) != 0) return Status::OK();
  if (!S_ISREG(st.st_mode))
    return Status::InvalidArgument(key + ": not a regular file (a PEM file with the private key and the certificate chain)");
  if ((st.st_mode & 077) != 0) return Status::InvalidArgument(key + ": holds a private key and is readable by others: chmod 600 it");
  return Status::OK();
}

// One line per address the server answers on: each page with the token of the role it is for.
void WebComponent::LogUrls() const {
  const bool tls = !options_.tls_certificate.empty();
  const std::string http = tls ? "https://" : "http://", ws = tls ? "wss://" : "ws://";
  // Bound to a wildcard address, the URLs name the machine's real addresses (0.0.0.0 opens nothing).
  for (const std::string& host : UrlHosts(options_.address)) {
    const std::string base = host + ":" + std::to_string(server_->port());
    ctx_->log().Info("subject's page: " + http + base + "/subject?token=" + shown_.at(Role::kSubject) +
                     "  experimenter's page: " + http + base + "/experimenter?token=" + shown_.at(Role::kExperimenter) +
                     "  Foxglove WebSocket: " + ws + base + "/?token=" + shown_.at(Role::kViewer) + " (viewer)" +
                     (writable_.empty() ? "" : ", or the experimenter's token to publish"));
  }
}

namespace {
// "median M ms, p99 P ms" of `ms`.
std::string MedianAndP99(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  char text[80];
  std::snprintf(text, sizeof text, "median %.2f ms, p99 %.2f ms", ms[ms.size() / 2], ms[std::min(ms.size() - 1, ms.size() * 99 / 100)]);
  return text;
}
}  // namespace

// Where the subject's pointer samples spent their time (bench/web/bench_web.sh prints both lines).
void WebComponent::LogPointerDelays() {
  const SubjectChannel::PointerDelays d = subject_->pointer_delays();
  if (d.total.empty()) return;
  ctx_->log().Info("pointer event -> published: " + MedianAndP99(d.total) + " (" + std::to_string(d.total.size()) + " samples)");
  if (d.page_to_socket.empty()) return;
  ctx_->log().Info("pointer hops: page -> socket " + MedianAndP99(d.page_to_socket) + "; socket -> handler thread " +
                   MedianAndP99(d.socket_to_handler) + "; handler -> published " + MedianAndP99(d.handler_to_published));
}

}  // namespace dyad::web

DYAD_PLUGIN(registry) {
  registry.Add<dyad::web::WebComponent>("web");
  registry.Add<dyad::web::WebHuman>("web_human");
}
