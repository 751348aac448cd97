// `dyad param get|set` (dyad/guest.hpp): one live parameter request and its answer.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <ostream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "dyad/guest.hpp"
#include "dyad/interrupt.hpp"
#include "dyad/join_list.hpp"
#include "dyad/validate.hpp"
#include "exec/wall_clock.hpp"
#include "graph/runtime_topics.hpp"
#include "hosts/watcher_join.hpp"

namespace dyad {
namespace {

// The graph's process of the component, after checking the request against the graph file; ""
// after saying what is wrong. `*value`: the value to ask for (a relative path made absolute
// against the working folder, as `--set` does: the process may run elsewhere).
std::string CheckAgainstGraph(const ParamRequest& r, const Catalog& catalog, std::string* value, std::ostream& err) {
  const std::string what = "dyad param: " + r.component + "." + r.param;
  std::vector<Diagnostic> diags;
  const ResolvedGraph resolved = ValidateGraph(*r.watched, catalog, &diags);
  for (const auto& d : diags) err << d.ToString() << "\n";
  if (!diags.empty()) return "";
  const ResolvedComponent* rc = nullptr;
  std::vector<std::string> names;
  for (const auto& c : resolved.components) {
    names.push_back(c.config->name);
    if (c.config->name == r.component) rc = &c;
  }
  if (rc == nullptr) {
    err << what << ": graph '" << r.watched->name << "' has no component '" << r.component << "' (components: " << JoinList(names) << ")\n";
    return "";
  }
  std::vector<std::string> live;
  for (const auto& p : rc->entry->spec.params())
    if (p.live) live.push_back(p.name);
  const std::string live_list = " (live params of " + r.component + ": " + (live.empty() ? "none" : JoinList(live)) + ")";
  const ParamSpec* spec = rc->entry->spec.FindParam(r.param);
  if (spec == nullptr) {
    err << what << ": " << rc->config->type << " has no parameter '" << r.param << "'" << live_list << "\n";
    return "";
  }
  if (!spec->live) {
    err << what << ": not live: " << rc->config->type << " reads it once, at configure" << live_list << "\n";
    return "";
  }
  if (r.set) {
    try {
      StatusOr<ParamValue> v = ParamFromYaml(*spec, YAML::Load(r.value));
      if (!v.ok()) {
        err << what << " = " << r.value << ": " << v.status().message() << "\n";
        return "";
      }
      *value = r.value;
      if (spec->path) {
        ResolvePaths(std::filesystem::current_path(), &v.value());
        *value = ToYamlText(*v);
      }
    } catch (const YAML::Exception& e) {
      err << what << " = " << r.value << ": not YAML: " << e.what() << "\n";
      return "";
    }
  }
  return r.watched->ProcessOf(*rc->config);
}

// Waits until the process's reader of the requests and writer of the answers are discovered and
// matched with this participant's writer and reader.
bool AwaitProcess(DdsParticipant& participant, const std::string& suffix, double wait_s, const InterruptWatcher& interrupt) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while (std::chrono::steady_clock::now() < end && !interrupt.interrupted()) {
    bool reader = false, writer = false;
    for (const auto& e : participant.Discovered()) {
      if (!e.participant.ends_with(suffix)) continue;
      reader = reader || (!e.writer && e.topic == runtime_topics::kParamRequests.name);
      writer = writer || (e.writer && e.topic == runtime_topics::kParams.name);
    }
    // Discovered, then matched with ours (a request written before the match would be lost).
    if (reader && writer && participant.MatchedReadersOf(runtime_topics::kParamRequests.name) > 0 &&
        participant.MatchedWritersOf(runtime_topics::kParams.name) > 0)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace

int RequestParam(const ParamRequest& r, const Catalog& catalog, std::ostream& out, std::ostream& err) {
  const std::string what = r.component + "." + r.param;
  std::string value;
  const std::string process = CheckAgainstGraph(r, catalog, &value, err);
  if (process.empty()) return 2;
  InterruptWatcher interrupt;
  std::unique_ptr<DdsParticipant> participant = JoinAsWatcher(r.watch, "dyad/guest/param/" + std::to_string(getpid()), err);
  if (!participant) return 1;
  auto requests = CreateRuntimeWriter(participant.get(), runtime_topics::kParamRequests);
  auto answers = CreateRuntimeReader(participant.get(), runtime_topics::kParams, nullptr, /*watcher=*/true);
  if (!requests.ok() || !answers.ok()) {
    err << "dyad param: " << (requests.ok() ? answers.status() : requests.status()).message() << "\n";
    return 1;
  }
  const auto asked = std::chrono::steady_clock::now();
  if (!AwaitProcess(*participant, "/" + r.watched->name + "/" + process, r.watch.wait_s, interrupt)) {
    if (interrupt.interrupted()) return ExitCodeForSignal(interrupt.signal());
    err << "dyad param: " << what << ": process '" << process << "' of graph '" << r.watched->name << "' not found on domain "
        << r.watch.domain_id << " within " << r.watch.wait_s << " s (is it running? a stepped run is private to its process)\n";
    return 1;
  }
  msg::ParamChange q;
  q.header().source("dyad/param");
  q.header().sequence_number(1);
  q.header().stamp_ns(WallNowNs());
  q.graph_name(r.watched->name);
  q.component_name(r.component);
  q.param_name(r.param);
  q.op(r.set ? "set" : "get");
  q.value(r.set ? value : "");
  q.who(r.who);
  q.request_id(r.who + "/" + std::to_string(getpid()) + "/" + std::to_string(WallNowNs()));
  if (Status s = (*requests)->Write(&q); !s.ok()) {
    err << "dyad param: " << s.message() << "\n";
    return 1;
  }
  const auto end = asked + std::chrono::duration<double>(r.watch.wait_s);
  msg::ParamChange a;
  while (std::chrono::steady_clock::now() < end && !interrupt.interrupted()) {
    while ((*answers)->TakeNext(&a)) {
      if (a.request_id() != q.request_id()) continue;
      if (a.op() == "refused") {
        err << "dyad param: " << what << " = " << r.value << ": refused by " << process << ": " << a.reason() << "\n";
        return 1;
      }
      if (a.op() == "applied")
        out << what << ": " << a.old_value() << " -> " << a.value() << " (from step " << a.step() << " of " << r.component << ")\n";
      else
        out << what << ": " << a.value() << "\n";
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (interrupt.interrupted()) return ExitCodeForSignal(interrupt.signal());
  err << "dyad param: " << what << ": no answer from process '" << process << "' within " << r.watch.wait_s
      << " s (the component answers at its next step: is it stepping?)\n";
  return 1;
}

}  // namespace dyad
