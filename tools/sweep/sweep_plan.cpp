#include "sweep_plan.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "dyad/graph.hpp"
#include "dyad/run.hpp"
#include "dyad/strict_yaml.hpp"

namespace dyad::sweep {
namespace {

namespace fs = std::filesystem;

// A value as `--set` takes it: a scalar as written, anything else as flow YAML.
std::string ValueText(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

// FNV-1a: stable across builds and machines (a run's id names its folder).
uint64_t Fnv1a(const std::string& s, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

struct Override {
  std::string key, value;
  YAML::Node node;  // where the sweep file wrote the value
  std::string where;  // "grid.KEY" or "runs[i].KEY"
};

// Reads the parts of the file; the overrides it names go to *swept (grid) or *listed (runs).
void ReadFile(StrictYaml& y, const YAML::Node& root, const std::string& path, SweepPlan* plan,
              std::vector<std::string>* base_sets, std::vector<std::vector<Override>>* grid,
              std::vector<std::vector<Override>>* listed, std::vector<int64_t>* seeds) {
  if (y.Get(root, "sweep", "sweep", &plan->name, "a name", true) &&
      (plan->name.empty() || plan->name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
                                 std::string::npos))
    y.Error(root["sweep"], "sweep", "a name is letters, digits, '_' and '-'");
  std::string graph;
  if (y.Get(root, "graph", "graph", &graph, "a path", true)) {
    fs::path g(graph);
    if (g.is_relative()) g = fs::absolute(fs::path(path).parent_path()) / g;
    std::error_code ec;
    if (!fs::is_regular_file(g, ec)) y.Error(root["graph"], "graph", "no such file: " + g.lexically_normal().string());
    plan->graph = g.lexically_normal().string();
  }
  if (y.Get(root, "duration", "duration", &plan->duration_s, "a number of seconds", true) && !(plan->duration_s > 0))
    y.Error(root["duration"], "duration", "must be > 0");
  y.Get(root, "recorder", "recorder", &plan->recorder, "a component name");
  if (const YAML::Node set = root["set"]; set && y.Map(set, "set", {}))
    for (const auto& kv : set) base_sets->push_back(kv.first.Scalar() + "=" + ValueText(kv.second));
  const YAML::Node g = root["grid"], r = root["runs"];
  if (g && r) y.Error(root["runs"], "runs", "give grid or runs, not both");
  if (!g && !r) y.Error(root, "grid", "required key missing (or runs)");
  if (g && y.Map(g, "grid", {})) {
    if (g.size() == 0) y.Error(g, "grid", "an empty grid: name at least one key and its values");
    for (const auto& kv : g) {
      const std::string key = kv.first.Scalar(), where = "grid." + key;
      if (!kv.second.IsSequence() || kv.second.size() == 0) {
        y.Error(kv.second, where, "must be a non-empty list of values");
        continue;
      }
      plan->parameters.push_back(key);
      grid->emplace_back();
      for (const auto& v : kv.second) grid->back().push_back({key, ValueText(v), v, where});
    }
  }
  if (r) {
    if (!r.IsSequence() || r.size() == 0) {
      y.Error(r, "runs", "must be a non-empty list of override sets");
    } else {
      for (size_t i = 0; i < r.size(); ++i) {
        const std::string where = "runs[" + std::to_string(i) + "]";
        if (!y.Map(r[i], where, {})) continue;
        listed->emplace_back();
        for (const auto& kv : r[i]) {
          const std::string key = kv.first.Scalar();
          if (std::find(plan->parameters.begin(), plan->parameters.end(), key) == plan->parameters.end())
            plan->parameters.push_back(key);
          listed->back().push_back({key, ValueText(kv.second), kv.second, where + "." + key});
        }
      }
    }
  }
  seeds->clear();
  if (const YAML::Node s = root["seeds"]) {
    std::vector<int64_t> given;
    if (y.Get(s, "seeds", &given, "a list of integers")) {
      if (given.empty()) y.Error(s, "seeds", "must name at least one seed");
      if (std::set<int64_t>(given.begin(), given.end()).size() != given.size()) y.Error(s, "seeds", "a seed is repeated");
      *seeds = given;
    }
  } else {
    seeds->push_back(1);
  }
}

// The graph's own verdict on `sets` (as `dyad validate --set`): empty when it passes.
std::string Check(const std::string& graph, const std::vector<std::string>& sets, const std::vector<std::string>& plugins) {
  std::vector<dyad::Override> overrides;
  for (const auto& s : sets) overrides.push_back({s});
  std::ostringstream out, err;
  if (ValidateGraphFile(graph, overrides, plugins, out, err) == 0) return "";
  std::string text = err.str();
  while (!text.empty() && text.back() == '\n') text.pop_back();
  // Its closing "GRAPH: N problems, nothing was started" is about a run that is not this sweep.
  if (const size_t last = text.rfind('\n'); last != std::string::npos && text.find("nothing was started", last) != std::string::npos)
    text.erase(last);
  return text.empty() ? "the graph does not validate" : text;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The combinations: the grid's product (first key slowest), or the list as given.
std::vector<std::vector<const Override*>> Combinations(const std::vector<std::vector<Override>>& grid,
                                                      const std::vector<std::vector<Override>>& listed) {
  std::vector<std::vector<const Override*>> combos;
  if (grid.empty()) {
    for (const auto& run : listed) {
      combos.emplace_back();
      for (const auto& o : run) combos.back().push_back(&o);
    }
    return combos;
  }
  combos.emplace_back();
  for (const auto& values : grid) {
    std::vector<std::vector<const Override*>> next;
    for (const auto& combo : combos)
      for (const auto& v : values) {
        next.push_back(combo);
        next.back().push_back(&v);
      }
    combos = std::move(next);
  }
  return combos;
}

}  // namespace

SweepPlan LoadSweep(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems) {
  SweepPlan plan;
  plan.file = path;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    problems->push_back({SourceMark{path, 0, 0}, "", "cannot read the sweep file"});
    return plan;
  } catch (const YAML::Exception& e) {
    problems->push_back({SourceMark{path, e.mark.line + 1, e.mark.column + 1}, "", e.msg});
    return plan;
  }
  StrictYaml y(StrictYaml::InFile(path, {}), problems);
  if (!y.Map(root, "", {"sweep", "graph", "duration", "recorder", "set", "grid", "runs", "seeds"})) return plan;
  std::vector<std::string> base;
  std::vector<std::vector<Override>> grid, listed;
  std::vector<int64_t> seeds;
  ReadFile(y, root, path, &plan, &base, &grid, &listed, &seeds);
  if (!problems->empty()) return plan;

  // Hermetic and deterministic: stepped, and the recording where the sweep says.
  base.push_back("clock=stepped");
  base.push_back(plan.recorder + ".overwrite=true");
  if (std::string why = Check(plan.graph, base, plugins); !why.empty()) {
    y.Error(root["set"] ? root["set"] : root, root["set"] ? "set" : "graph", "the graph with these overrides does not validate:\n" + why);
    return plan;
  }
  std::set<std::string> checked;
  auto check = [&](const Override& o) {
    if (!checked.insert(o.key + "=" + o.value).second) return;
    std::vector<std::string> sets = base;
    sets.push_back(o.key + "=" + o.value);
    if (std::string why = Check(plan.graph, sets, plugins); !why.empty()) y.Error(o.node, o.where, "does not validate:\n" + why);
  };
  for (const auto& values : grid)
    for (const auto& o : values) check(o);
  for (const auto& run : listed)
    for (const auto& o : run) check(o);
  if (!problems->empty()) return plan;

  const std::vector<std::vector<const Override*>> combos = Combinations(grid, listed);
  const std::string graph_text = ReadText(plan.graph);
  for (const auto& combo : combos)
    for (int64_t seed : seeds) {
      SweepRun run;
      run.seed = seed;
      run.sets = base;
      for (const Override* o : combo) {
        run.params.emplace_back(o->key, o->value);
        run.sets.push_back(o->key + "=" + o->value);
      }
      run.sets.push_back("seed=" + std::to_string(seed));
      uint64_t h = Fnv1a(graph_text);
      for (const auto& s : run.sets) h = Fnv1a(s + "\n", h);
      h = Fnv1a(DYAD_VERSION, h);
      char id[17];
      std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(h));
      run.id = id;
      plan.runs.push_back(std::move(run));
    }
  return plan;
}

}  // namespace dyad::sweep
