#include "web_component.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <random>
#include <set>

#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include <dyad/decode_sample.hpp>
#include <dyad/graph.hpp>
#include <dyad/on_demand_subscription.hpp>
#include <dyad/private_file.hpp>
#include <dyad/pvrnn/dataset.hpp>
#include <dyad/topic_select.hpp>

#include "pages.hpp"
#include "web_human.hpp"

namespace dyad::web {
namespace {

// The token kept in `path` (params.token_file): a regular file, not a link, readable by its owner
// only, holding one token of 16..256 printable characters (a newline after it is allowed).
StatusOr<std::string> ReadTokenFile(const std::string& path) {
  const std::string key = "params.token_file = '" + path + "': ";
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return Status::NotFound(key + "missing");
  if (S_ISLNK(st.st_mode) || !S_ISREG(st.st_mode)) return Status::InvalidArgument(key + "not a regular file (a link is refused)");
  if ((st.st_mode & 077) != 0) return Status::InvalidArgument(key + "readable by others: chmod 600 it");
  std::ifstream in(path);
  std::string token;
  std::getline(in, token);
  if (token.size() < 16 || token.size() > 256 ||
      !std::all_of(token.begin(), token.end(), [](char c) { return c > ' ' && c < 127 && c != '&' && c != '#'; }))
    return Status::InvalidArgument(key + "must hold one token of 16..256 printable characters without spaces, '&' or '#'");
  return token;
}

std::string RandomToken() {
  std::random_device rd;
  static const char* hex = "0123456789abcdef";
  std::string t;
  for (int i = 0; i < 32; ++i) t.push_back(hex[rd() % 16]);
  return t;
}

// Every (process, component) of the graph as run, placed as the runtime places them.
std::set<std::pair<std::string, std::string>> GraphsComponents(const Context& ctx) {
  std::vector<Diagnostic> diags;  // the runtime parsed this text before: none
  const Graph g = ParseGraph(ctx.graph_yaml(), ctx.graph_folder() + "/graph.yaml", {}, &diags);
  std::set<std::pair<std::string, std::string>> out;
  for (const auto& c : g.components) out.insert({g.ProcessOf(c), c.name});
  return out;
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

// The newest ComponentStats of every component of the graph, from dyad/stats (any process). Only
// the graph's own (process, component) pairs are kept: a peer sending other names cannot grow
// the table (or the experimenter's page).
struct WebComponent::StatsTable {
  std::mutex mutex;
  std::set<std::pair<std::string, std::string>> graphs_own;  // (process, component); set before subscribing
  std::map<std::pair<std::string, std::string>, msg::ComponentStats> rows;  // (process, component)
  void Add(std::span<const uint8_t> cdr) {
    msg::ComponentStats s;
    if (!DecodeSample(cdr, &s).ok()) return;  // not from a dyad runtime of this version: not shown
    if (!graphs_own.count({s.process_name(), s.component_name()})) return;
    std::lock_guard<std::mutex> lock(mutex);
    rows[{s.process_name(), s.component_name()}] = std::move(s);
  }
  std::string Json() {
    nlohmann::json list = nlohmann::json::array();
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [key, s] : rows)
      list.push_back({{"process", s.process_name()}, {"component", s.component_name()}, {"steps", s.steps()},
                      {"mean_ms", s.step_mean_s() * 1e3}, {"p99_ms", s.step_p99_s() * 1e3}, {"max_ms", s.step_max_s() * 1e3},
                      {"misses", s.deadline_misses()}});
    return nlohmann::json{{"op", "stats"}, {"rows", list}}.dump();
  }
};

void WebComponent::Describe(ComponentSpec& spec) {
  spec.Summary("Embedded web server with a live Foxglove WebSocket bridge over the graph's topics.");
  spec.Param("address", "127.0.0.1").Doc("address to bind; anything but loopback requires a token");
  spec.Param("port", 8765).Range(0, 65535).Doc("TCP port; 0 picks a free one (see port_file)");
  spec.Param("topics", std::vector<std::string>{}).Doc("topics to advertise, by name or regular expression (empty: all)");
  spec.Param("writable", std::vector<std::string>{}).Doc("topics Foxglove clients may publish on (empty: none)");
  spec.Param("token", "").Secret().Doc("clients must connect with ?token=...; empty: token_file's, DYAD_WEB_TOKEN, none on "
                                       "loopback, else generated and printed (kept out of recordings)");
  spec.Param("token_file", "").Path().Doc("a 0600 file holding the token: read when it exists, else created with a new one "
                                          "(bookmarked pages keep working across runs); the token is then not printed");
  spec.Param("allowed_origins", std::vector<std::string>{}).Doc("browser origins allowed besides localhost ('*': any)");
  spec.Param("max_clients", 8).Range(1, 64).Doc("WebSocket clients at once");
  spec.Param("client_buffer_kb", 4096).Range(16, 1 << 20).Doc("per-client send buffer; past it the busiest channel's oldest samples are dropped");
  spec.Param("max_frame_kb", 1024).Range(1, 1 << 20).Doc("a larger frame from a client closes it");
  spec.Param("port_file", "").Path().Doc("write the bound port to this file (tests, scripts)");
  spec.Param("engage_key", "Space").Doc("subject's page: the key (KeyboardEvent.code) that engages while held, besides the mouse button");
  spec.Param("half_width", 50.0).Min(1e-6).Doc("subject's page: the workspace drawn is [-half_width, half_width]^2 (the study's 50)");
  spec.Param("show_primitives", false).Doc("subject's page: draw the data set's primitives as a faint watermark");
  spec.Param("dataset", "").Path().Doc("subject's page: NRL data set folder of the primitives (with show_primitives)");
  spec.Input<msg::CartesianState>("robot").Optional().Doc("robot state shown on the subject's page");
  spec.Input<msg::Intention>("intention").Optional().Doc("experimenter's page: the deliberator's N-ELBO");
  spec.Input<msg::IntentionLabel>("labels").Optional().Doc("experimenter's page: the observer's P(C_t) and labels");
  spec.Output<msg::Annotation>("notes").Doc("experimenter's notes (record this topic to align them with the run)");
  spec.Output<msg::HumanInput>("pointer").Doc("the steering page's pointer, at the browser's event rate (to web_human)");
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

  // Where the token comes from, said in the printed URLs instead of the token itself; only a
  // token dyad draws and keeps nowhere else is printed (else nobody could use it).
  options_.token = p.String("token");
  token_shown_ = "<params.token>";
  if (options_.token.empty())
    if (const char* env = std::getenv("DYAD_WEB_TOKEN")) {
      options_.token = env;
      token_shown_ = "<$DYAD_WEB_TOKEN>";
    }
  token_file_ = p.String("token_file");
  create_token_file_ = false;
  if (options_.token.empty() && !token_file_.empty()) {
    auto kept = ReadTokenFile(token_file_);
    token_shown_ = "<the token in " + token_file_ + ">";
    if (kept.ok()) {
      options_.token = kept.value();
    } else if (kept.status().code() == Status::Code::kNotFound) {
      options_.token = RandomToken();  // the file is created at Activate (Configure acts on nothing)
      create_token_file_ = true;
    } else {
      return kept.status();
    }
  }
  if (options_.token.empty() && !IsLoopback(options_.address)) {
    options_.token = RandomToken();
    token_shown_ = options_.token;
  }
  port_file_ = p.String("port_file");

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

  SubjectChannel::Options so;
  so.engage_key = p.String("engage_key");
  so.half_width = p.Double("half_width");
  so.token = options_.token;
  if (p.Bool("show_primitives")) {
    if (p.String("dataset").empty()) return Status::InvalidArgument("params.show_primitives: needs params.dataset (an NRL data set folder)");
    auto data = pvrnn::LoadNrlDataset(p.String("dataset"));
    if (!data.ok()) return data.status().WithContext("params.dataset");
    for (const auto& seq : data->sequences) {
      if (seq.rows() < 2) return Status::InvalidArgument("params.dataset: primitives need 2 DOFs (x, y), got " + std::to_string(seq.rows()));
      std::vector<std::array<double, 2>> pts;
      for (Eigen::Index t = 0; t < seq.cols(); ++t) pts.push_back({seq(0, t), seq(1, t)});
      so.primitives.push_back(std::move(pts));
    }
  }
  robot_ = &ctx.input<msg::CartesianState>("robot");
  pointer_ = &ctx.output<msg::HumanInput>("pointer");
  subject_ = std::make_unique<SubjectChannel>(so, [this](double x, double y, bool engaged) {
    pointer_sample_.x(x);
    pointer_sample_.y(y);
    pointer_sample_.engaged(engaged);
    // Serialised by SubjectChannel (component.hpp: one Output's Publish calls must not overlap).
    if (Status s = pointer_->Publish(pointer_sample_); !s.ok()) ctx_->log().Warn("pointer: " + s.ToString());
  });

  intention_ = &ctx.input<msg::Intention>("intention");
  labels_ = &ctx.input<msg::IntentionLabel>("labels");
  notes_ = &ctx.output<msg::Annotation>("notes");
  experimenter_ = std::make_unique<ExperimenterChannel>([this](const std::string& text) {
    note_.author("experimenter");
    note_.text(text);
    // Serialised by ExperimenterChannel.
    if (Status s = notes_->Publish(note_); !s.ok()) ctx_->log().Warn("notes: experimenter's note lost: " + s.ToString());
  });
  stats_ = std::make_shared<StatsTable>();
  stats_->graphs_own = GraphsComponents(ctx);
  events_ = std::make_shared<RunEvents>();
  for (const auto& t : ctx.graph_topics()) {
    Status s;
    if (t.name == "dyad/stats") {
      std::shared_ptr<StatsTable> table = stats_;
      s = ctx.SubscribeSerialized(t.name, [table](const SerializedSample& sample) { table->Add(sample.cdr); });
    } else if (t.name == "dyad/processes") {
      s = ctx.SubscribeSerialized(t.name, [events = events_](const SerializedSample& sample) { AddEvent<msg::ProcessState>(*events, sample); });
    } else if (t.name == "dyad/health") {
      s = ctx.SubscribeSerialized(t.name, [events = events_](const SerializedSample& sample) { AddEvent<msg::HealthEvent>(*events, sample); });
    }
    if (!s.ok()) return s;
  }

  options_.pages["/"] = WebServer::Page{"text/html; charset=utf-8", kIndexHtml, ""};
  options_.pages["/subject"] = WebServer::Page{"text/html; charset=utf-8", kSubjectHtml, ""};
  options_.pages["/experimenter"] = WebServer::Page{"text/html; charset=utf-8", kExperimenterHtml, ""};
  options_.endpoints = {
      WebServer::Endpoint{"/", {foxglove::kSubprotocol, foxglove::kSubprotocolSdk}, bridge_.get()},
      // The subject steers by the robot state on this page: no batching delay.
      WebServer::Endpoint{"/subject/ws", {}, subject_.get(), /*viewers=*/false},
      WebServer::Endpoint{"/experimenter/ws", {}, experimenter_.get()},
  };
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

Status WebComponent::Activate() {
  auto s = WebServer::Start(options_);
  if (!s.ok()) return s.status().WithContext("params.address/port");
  server_ = std::move(s.value());
  bridge_->SetServer(server_.get());
  subject_->SetServer(server_.get());
  experimenter_->SetServer(server_.get());
  if (create_token_file_) {
    if (Status s = WritePrivateFile(token_file_, options_.token + "\n", CreateMode::kNew); !s.ok())
      return s.WithContext("params.token_file");
  }
  // Bound to a wildcard address, the URLs name the machine's real addresses (0.0.0.0 opens nothing).
  const std::string query = options_.token.empty() ? "" : "?token=" + token_shown_;
  for (const std::string& host : UrlHosts(options_.address)) {
    const std::string base = host + ":" + std::to_string(server_->port());
    ctx_->log().Info("subject's page: http://" + base + "/subject" + query + "  experimenter: http://" + base +
                     "/experimenter" + query + "  Foxglove WebSocket: ws://" + base + "/" + query);
  }
  if (!port_file_.empty()) {
    std::ofstream f(port_file_);
    f << server_->port() << "\n";
    if (!f) return Status::IOError("params.port_file = '" + port_file_ + "': cannot write");
  }
  return Status::OK();
}

Status WebComponent::Step(const StepInfo& info) {
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
  LogPointerDelays();
  return Status::OK();
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
