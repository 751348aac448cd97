#include "study_file.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "dyad/graph.hpp"
#include "dyad/join_list.hpp"
#include "dyad/strict_yaml.hpp"
#include "graph_check.hpp"
#include "yaml_file.hpp"
#include "latin_square.hpp"

namespace dyad::study {
namespace {

namespace fs = std::filesystem;


bool IsName(const std::string& s) {
  return !s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") == std::string::npos;
}


void ReadScalars(StrictYaml& y, const YAML::Node& root, const std::string& path, Study* s) {
  if (y.Get(root, "study", "study", &s->name, "a name", true) && !IsName(s->name))
    y.Error(root["study"], "study", "a name is letters, digits, '_' and '-'");
  std::string graph;
  if (y.Get(root, "graph", "graph", &graph, "a path", true)) {
    const std::string g = tools::PathBeside(path, graph);
    std::error_code ec;
    if (fs::is_regular_file(g, ec)) s->graph = g;
    else y.Error(root["graph"], "graph", "no such file: " + g);
  }
  std::string data = s->name + "-data";
  y.Get(root, "data", "data", &data, "a path");
  s->data = tools::PathBeside(path, data);
  if (y.Get(root, "trials", "trials", &s->trials, "an integer") && (s->trials < 1 || s->trials > 99))
    y.Error(root["trials"], "trials", "must be in 1..99");
  if (y.Get(root, "duration", "duration", &s->duration_s, "a number of seconds") && !(s->duration_s >= 0))
    y.Error(root["duration"], "duration", "must be >= 0 (0: until the experimenter stops the trial)");
  y.Get(root, "blind", "blind", &s->blind, "true or false");
  y.Get(root, "consent_required", "consent_required", &s->consent_required, "true or false");
  if (std::string word; y.Get(root, "self_reports", "self_reports", &word, "a word")) {
    if (auto when = ParseSelfReports(word); when.ok()) s->self_reports = *when;
    else y.Error(root["self_reports"], "self_reports", when.status().message());
  }
}

void ReadParticipants(StrictYaml& y, const YAML::Node& root, Study* s) {
  const YAML::Node list = root["participants"];
  if (!list) return y.Error(root, "participants", "required key missing");
  if (!list.IsSequence() || list.size() == 0) return y.Error(list, "participants", "must be a non-empty list of IDs");
  static const std::regex pseudonym("[A-Za-z]{1,4}[0-9]{1,4}");
  // By the ID in lower case: AB12 and ab12 would share a folder on a case-insensitive file system.
  std::map<std::string, std::pair<std::string, YAML::Node>> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = "participants[" + std::to_string(i) + "]";
    std::string id;
    if (!y.Get(list[i], key, &id, "an ID")) continue;
    std::string folded = id;
    std::transform(folded.begin(), folded.end(), folded.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (!std::regex_match(id, pseudonym)) {
      y.Error(list[i], key, "'" + id + "' is not a pseudonymous ID: 1-4 letters then 1-4 digits, such as P01 (never a name)");
    } else if (auto it = seen.find(folded); it != seen.end()) {
      const std::string line = std::to_string(it->second.second.Mark().line + 1);
      y.Error(list[i], key, it->second.first == id ? "participant " + id + " is listed twice (first at line " + line + ")"
                                                   : "participant " + id + " is " + it->second.first + " (line " + line +
                                                         ") in another case: IDs must differ in more than case (their folders "
                                                         "would be one on a case-insensitive file system)");
    } else {
      seen.emplace(folded, std::make_pair(id, list[i]));
      s->participants.push_back(id);
    }
  }
}

// The conditions; each override is checked against the graph at its line, then each condition
// whole. Adds to `bad_conditions` those a problem was said of (the rehearsal's check skips them).
void ReadConditions(StrictYaml& y, const YAML::Node& root, const std::vector<std::string>& plugins, Study* s,
                    std::set<std::string>* bad_conditions) {
  const YAML::Node conditions = root["conditions"];
  if (!conditions) return y.Error(root, "conditions", "required key missing");
  if (!y.Map(conditions, "conditions", {})) return;
  if (conditions.size() == 0) return y.Error(conditions, "conditions", "name at least one condition and its overrides");
  for (const auto& kv : conditions) {
    const std::string name = kv.first.Scalar(), where = "conditions." + name;
    if (!IsName(name)) y.Error(kv.first, where, "a condition's name is letters, digits, '_' and '-'");
    if (!y.Map(kv.second, where, {})) continue;
    if (kv.second.size() == 0) y.Error(kv.second, where, "overrides nothing: name the keys it changes");
    Condition c{name, "", {}, s->task};
    bool bad = false;
    for (const auto& o : kv.second) {
      if (o.first.Scalar() == "task") {  // not an override: what the subject's page shows (study_task.hpp)
        bad = !ReadTask(y, o.second, where + ".task", &c.task) || bad;
        continue;
      }
      const std::string set = o.first.Scalar() + "=" + tools::SetText(o.second);
      if (s->graph.empty()) continue;
      if (std::string why = tools::GraphProblems(s->graph, {"clock=stepped", set}, plugins); !why.empty()) {
        y.Error(o.second, where + "." + o.first.Scalar(), "does not validate:\n" + why);
        bad = true;
      }
      c.sets.push_back(set);
    }
    if (!bad && !s->graph.empty() && c.sets.size() > 1)
      if (std::string why = tools::GraphProblems(s->graph, c.sets, plugins); !why.empty()) {
        y.Error(kv.second, where, "its overrides together do not validate:\n" + why);
        bad = true;
      }
    if (bad) bad_conditions->insert(name);
    s->conditions.push_back(std::move(c));
  }
}

// The session-long subject's link (subject_lobby.hpp): the graph's one web component, when a
// person steers from its page, the runner gives it its token file and it speaks plain HTTP.
void ChooseSubjectWeb(const Graph& graph, const std::vector<std::string>& webs, bool subject_steers, Study* s) {
  if (webs.size() != 1 || !subject_steers || s->token_file_webs.size() != 1) return;
  for (const ComponentConfig& c : graph.components) {
    if (c.name != webs[0]) continue;
    if (c.params && c.params["tls_certificate"]) return;
    s->subject_web = c.name;
    try {
      if (c.params && c.params["address"]) s->subject_address = c.params["address"].as<std::string>();
      if (c.params && c.params["port"]) s->subject_port = c.params["port"].as<int>();
    } catch (const YAML::Exception&) {
      s->subject_web.clear();  // the graph's own check says what is wrong
    }
  }
}

// `recorder` and `rehearsal`, after the conditions: the rehearsal graph is checked against each.
void ReadRehearsal(StrictYaml& y, const YAML::Node& root, const std::string& path, const std::vector<std::string>& plugins,
                   const std::set<std::string>& bad_conditions, Study* s) {
  y.Get(root, "recorder", "recorder", &s->recorder, "a component name");
  if (!s->graph.empty())
    if (std::string why = tools::GraphProblems(s->graph, {"clock=stepped", s->recorder + ".metadata=[study=" + s->name + "]"}, plugins);
        !why.empty())
      y.Error(root["recorder"] ? root["recorder"] : root, "recorder", "the graph's recorder '" + s->recorder + "' cannot record a trial:\n" + why);
  // Whether the subject's page asks: each `web` component of the graph is told.
  if (!s->graph.empty()) {
    std::vector<Diagnostic> ignored;  // the graph's own problems were said above
    std::vector<std::string> webs, answering;  // the web components; those whose answers are recorded
    std::set<std::string> processes;
    bool subject_steers = false;  // a web_human: a person steers from the subject's page
    const Graph graph = LoadGraph(s->graph, {}, &ignored);
    s->graph_domain = graph.domain_id;
    for (const ComponentConfig& c : graph.components) {
      processes.insert(graph.ProcessOf(c));
      if (c.type == "web") {
        webs.push_back(c.name);
        for (const PortBinding& out : c.outputs)
          if (out.port == "self_report" && !out.topic.empty()) answering.push_back(c.name);
        s->page_sets.push_back(c.name + ".self_reports=" + std::string(ToString(s->self_reports)));
        // After the trial the page asks, then ends the run: at the trial's duration.
        if (s->self_reports == SelfReports::kAfterTrial && s->duration_s > 0)
          s->page_sets.push_back(c.name + ".ask_after_s=" + tools::SetText(YAML::Node(s->duration_s)));
        // The same tokens for every trial of a participant (each participant their own), so the
        // pages reconnect to the next trial's graph.
        if (!c.params || !c.params["token_file"]) s->token_file_webs.push_back(c.name);
      }
      subject_steers = subject_steers || c.type == "web_human";
    }
    ChooseSubjectWeb(graph, webs, subject_steers, s);
    // The one page that asks after the trial also ends it: two would end it at the first's end.
    if (s->self_reports == SelfReports::kAfterTrial && (webs.size() != 1 || answering.size() != 1))
      y.Error(root["self_reports"], "self_reports",
              "after_trial needs the graph's one `web` component (its subject's page asks, then ends the trial) with its "
              "self_report output bound; " + s->graph + " has " +
                  (webs.empty() ? std::string("none")
                                : std::to_string(webs.size()) + " (" + JoinList(webs) + "), " +
                                      std::to_string(answering.size()) + " binding self_report"));
    // A component's end of the run ends its own process only: the others would run on.
    else if (s->self_reports == SelfReports::kAfterTrial && processes.size() > 1)
      y.Error(root["self_reports"], "self_reports",
              "after_trial needs the graph in one process (the page ends the run of its own process only); " + s->graph +
                  " has " + std::to_string(processes.size()) + " (" + JoinList(processes) + ")");
  }
  s->rehearsal_graph = s->graph;
  const YAML::Node r = root["rehearsal"];
  if (!r) return;
  if (!y.Map(r, "rehearsal", {"graph", "set"})) return;
  std::string graph;
  if (y.Get(r, "graph", "rehearsal.graph", &graph, "a path")) {
    const std::string g = tools::PathBeside(path, graph);
    std::error_code ec;
    if (!fs::is_regular_file(g, ec)) return y.Error(r["graph"], "rehearsal.graph", "no such file: " + g);
    s->rehearsal_graph = g;
  }
  if (const YAML::Node set = r["set"]; set && y.Map(set, "rehearsal.set", {}))
    for (const auto& kv : set) s->rehearsal_sets.push_back(kv.first.Scalar() + "=" + tools::SetText(kv.second));
  if (s->rehearsal_graph.empty()) return;
  for (const Condition& c : s->conditions) {
    // Its problem was said at its line: said again here it would be said twice (the study's own graph).
    if (bad_conditions.count(c.name)) continue;
    std::vector<std::string> sets = {"clock=stepped"};
    sets.insert(sets.end(), c.sets.begin(), c.sets.end());
    sets.insert(sets.end(), s->rehearsal_sets.begin(), s->rehearsal_sets.end());
    if (std::string why = tools::GraphProblems(s->rehearsal_graph, sets, plugins); !why.empty())
      y.Error(r, "rehearsal", "condition " + c.name + " does not validate on the rehearsal graph " + s->rehearsal_graph + ":\n" + why);
  }
}

// The `online:` map (`dyad study serve`): its keys, each checked at its line; the consent text read.
void ReadOnline(StrictYaml& y, const YAML::Node& root, const std::string& path, Study* s) {
  const YAML::Node o = root["online"];
  if (!o || !y.Map(o, "online", {"reconnect_s", "max_sessions", "domains", "completion_code", "consent"})) return;
  Online& on = s->online;
  if (y.Get(o, "reconnect_s", "online.reconnect_s", &on.reconnect_s, "a number of seconds") && !(on.reconnect_s > 0))
    y.Error(o["reconnect_s"], "online.reconnect_s", "must be > 0 (how long a page gone mid-trial may take to come back)");
  bool sessions_ok = true, domains_ok = true;
  if (y.Get(o, "max_sessions", "online.max_sessions", &on.max_sessions, "an integer") && on.max_sessions < 1) {
    y.Error(o["max_sessions"], "online.max_sessions", "must be >= 1");
    sessions_ok = false;
  }
  if (std::vector<int> d; y.Get(o, "domains", "online.domains", &d, "[FIRST, LAST]: two DDS domain ids")) {
    auto range = d.size() == 2 ? ParseDomainRange(std::to_string(d[0]) + "-" + std::to_string(d[1]))
                               : StatusOr<DomainRange>(Status::InvalidArgument("want [FIRST, LAST]"));
    if (range.ok()) on.domains = *range;
    else y.Error(o["domains"], "online.domains", "must be [FIRST, LAST], two DDS domain ids in 0..232, FIRST <= LAST");
    domains_ok = range.ok();
  }
  // Room for max_sessions trials, each on a domain of its own: said here, at the key that limits
  // it, not first when `study serve` starts (which checks again with its --max-sessions and --domains).
  if (sessions_ok && domains_ok)
    if (const auto room = TrialDomainRange(on.domains, "", s->graph_domain, on.max_sessions); !room.ok()) {
      const char* key = on.domains ? "domains" : "max_sessions";
      y.Error(o[key] ? o[key] : o, std::string("online.") + key, std::string(room.status().message()));
    }
  static const std::regex code("[A-Za-z0-9_-]{1,64}");
  if (y.Get(o, "completion_code", "online.completion_code", &on.completion_code, "a code") &&
      !std::regex_match(on.completion_code, code)) {
    y.Error(o["completion_code"], "online.completion_code", "a code is 1-64 letters, digits, '_' and '-'");
    on.completion_code.clear();
  }
  std::string consent;
  if (!y.Get(o, "consent", "online.consent", &consent, "a path")) return;
  const std::string file = tools::PathBeside(path, consent);
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().find_first_not_of(" \t\r\n") == std::string::npos)
    return y.Error(o["consent"], "online.consent",
                   in ? file + " is empty: it holds the consent page's text" : "cannot read " + file);
  on.consent = file;
  on.consent_text = text.str();
}

// Labels A, B, ... in an order drawn from the study's name (the same on every machine).
void GiveLabels(Study* s) {
  uint64_t h = tools::Fnv1a(s->name);
  std::vector<size_t> order(s->conditions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (size_t i = order.size(); i > 1; --i) {
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    std::swap(order[i - 1], order[(h >> 33) % i]);
  }
  for (size_t i = 0; i < order.size(); ++i) s->conditions[order[i]].label = std::string(1, static_cast<char>('A' + i));
}

}  // namespace

std::vector<size_t> Study::ListingOrder() const {
  std::vector<size_t> order(conditions.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  if (blind)
    std::stable_sort(order.begin(), order.end(), [this](size_t a, size_t b) { return conditions[a].label < conditions[b].label; });
  return order;
}

std::vector<Trial> Study::TrialsOf(const std::string& participant) const {
  const auto it = std::find(participants.begin(), participants.end(), participant);
  if (it == participants.end() || conditions.empty()) return {};
  const auto rows = BalancedLatinSquare(static_cast<int>(conditions.size()));
  const auto& row = rows[static_cast<size_t>(it - participants.begin()) % rows.size()];
  std::vector<Trial> out;
  for (int c : row)
    for (int r = 1; r <= trials; ++r) {
      Trial t;
      t.number = static_cast<int>(out.size()) + 1;
      t.condition = c;
      t.repetition = r;
      char nn[16];
      std::snprintf(nn, sizeof nn, "%02d", t.number);
      const Condition& cond = conditions[static_cast<size_t>(c)];
      t.file = (fs::path(data) / participant / (std::string(nn) + "-" + (blind ? cond.label : cond.name) + ".mcap")).string();
      out.push_back(std::move(t));
    }
  return out;
}

Study LoadStudy(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems) {
  Study s;
  s.file = path;
  YAML::Node root;
  if (!tools::LoadYamlFile(path, "study", &root, problems)) return s;
  StrictYaml y(StrictYaml::InFile(path, {}), problems);
  if (!y.Map(root, "",
             {"study", "graph", "data", "participants", "conditions", "trials", "duration", "blind", "consent_required",
              "self_reports", "recorder", "rehearsal", "task", "online"}))
    return s;
  ReadScalars(y, root, path, &s);
  ReadParticipants(y, root, &s);
  std::set<std::string> bad_conditions;
  if (root["task"]) ReadTask(y, root["task"], "task", &s.task);
  ReadConditions(y, root, plugins, &s, &bad_conditions);  // checked against the graph when it was found
  ReadRehearsal(y, root, path, plugins, bad_conditions, &s);
  ReadOnline(y, root, path, &s);
  for (const Condition& c : s.conditions)
    if (c.task.any && s.subject_web.empty() && !s.graph.empty()) {
      y.Error(root["task"] ? root["task"] : root["conditions"], "task",
              "the graph has no subject's page to show it on (one `web` component and a `web_human`, as in "
              "configs/interactive.yaml)");
      break;
    }
  GiveLabels(&s);
  s.square_rows = static_cast<int>(BalancedLatinSquare(std::max(1, static_cast<int>(s.conditions.size()))).size());
  return s;
}

}  // namespace dyad::study
