#include "sweep_plan.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "dyad/catalog.hpp"
#include "dyad/graph.hpp"
#include "dyad/params.hpp"
#include "dyad/pvrnn/train_config.hpp"
#include "dyad/strict_yaml.hpp"
#include "dyad/validate.hpp"
#include "graph_check.hpp"
#include "study_file.hpp"
#include "yaml_file.hpp"

namespace dyad::sweep {
namespace {

namespace fs = std::filesystem;

struct SweptValue {
  std::string key, value;
  YAML::Node node;  // where the sweep file wrote the value
  std::string where;  // "grid.KEY" or "runs[i].KEY"
};

// A list of values per key (a grid), into *grid and *columns.
void ReadGrid(StrictYaml& y, const YAML::Node& g, const std::string& at, const std::string& column_prefix,
              std::vector<std::string>* columns, std::vector<std::vector<SweptValue>>* grid) {
  if (!y.Map(g, at, {})) return;
  if (g.size() == 0) y.Error(g, at, "an empty grid: name at least one key and its values");
  for (const auto& kv : g) {
    const std::string key = kv.first.Scalar(), where = at + "." + key;
    if (!kv.second.IsSequence() || kv.second.size() == 0) {
      y.Error(kv.second, where, "must be a non-empty list of values");
      continue;
    }
    columns->push_back(column_prefix + key);
    grid->emplace_back();
    std::set<std::string> seen;
    for (const auto& v : kv.second) {
      const std::string text = tools::SetText(v);
      // One id run twice at once into one folder, and counted twice in the plots' means.
      if (!seen.insert(text).second) y.Error(v, where, "the value " + text + " is repeated (each combination runs once per seed)");
      grid->back().push_back({key, text, v, where});
    }
  }
}

// The train: section (see the header).
void ReadTrain(StrictYaml& y, const YAML::Node& t, const std::string& path, SweepPlan* plan, std::vector<std::string>* base_sets,
               std::vector<std::vector<SweptValue>>* grid) {
  if (!y.Map(t, "train", {"config", "model", "set", "grid"})) return;
  std::string config;
  if (y.Get(t, "config", "train.config", &config, "a path", true)) {
    plan->train_config = tools::PathBeside(path, config);
    std::error_code ec;
    if (!fs::is_regular_file(plan->train_config, ec)) y.Error(t["config"], "train.config", "no such file: " + plan->train_config);
  }
  y.Get(t, "model", "train.model", &plan->model_key, "a graph key (COMPONENT.PARAM)");
  if (const YAML::Node set = t["set"]; set && y.Map(set, "train.set", {}))
    for (const auto& kv : set) base_sets->push_back(kv.first.Scalar() + "=" + tools::SetText(kv.second));
  if (t["grid"]) ReadGrid(y, t["grid"], "train.grid", "train.", &plan->parameters, grid);
}

// The base: `graph:`, or a study's `condition:` (the study's graph with that condition's
// overrides first, so the sweep varies around what the participants get).
void ReadBase(StrictYaml& y, const YAML::Node& root, const std::string& path, const std::vector<std::string>& plugins,
              SweepPlan* plan, std::vector<std::string>* base_sets, std::vector<Diagnostic>* problems) {
  const YAML::Node study_node = root["study"], condition_node = root["condition"];
  if (root["graph"] && study_node) return y.Error(study_node, "study", "give graph or study (with its condition), not both");
  if (!study_node) {
    if (condition_node) y.Error(condition_node, "condition", "a condition is a study's: give study too");
    std::string graph;
    if (!y.Get(root, "graph", "graph", &graph, "a path", true)) return;
    plan->graph = tools::PathBeside(path, graph);
    std::error_code ec;
    if (!fs::is_regular_file(plan->graph, ec)) y.Error(root["graph"], "graph", "no such file: " + plan->graph);
    return;
  }
  std::string file, condition;
  const bool named = y.Get(study_node, "study", &file, "a path");
  if (!y.Get(root, "condition", "condition", &condition, "a condition of the study", true) || !named) return;
  const std::string study_file = tools::PathBeside(path, file);
  std::error_code ec;
  if (!fs::is_regular_file(study_file, ec)) return y.Error(study_node, "study", "no such file: " + study_file);
  const size_t before = problems->size();
  const study::Study st = study::LoadStudy(study_file, plugins, problems);  // its problems at its lines
  if (problems->size() > before) return;
  std::string known;
  for (const auto& c : st.conditions) {
    if (c.name == condition) {
      plan->graph = st.graph;
      base_sets->insert(base_sets->begin(), c.sets.begin(), c.sets.end());
      return;
    }
    known += (known.empty() ? "" : ", ") + c.name;
  }
  y.Error(condition_node, "condition", "the study " + st.name + " has no condition '" + condition + "' (it has: " + known + ")");
}

// `seed` in the grid: the seeds (a column of their own in the table, and the last --set of each
// run, so a grid value would be overridden by the default seed), taken out of the grid.
void TakeGridSeeds(StrictYaml& y, const YAML::Node& root, SweepPlan* plan, std::vector<std::vector<SweptValue>>* grid,
                   std::vector<int64_t>* seeds) {
  for (size_t i = 0; i < grid->size(); ++i) {
    if ((*grid)[i].empty() || (*grid)[i][0].key != "seed") continue;
    const YAML::Node node = root["grid"]["seed"];
    if (root["seeds"]) y.Error(node, "grid.seed", "give the seeds once: in grid or as seeds:, not both");
    std::vector<int64_t> given;
    if (y.Get(node, "grid.seed", &given, "a list of integers")) *seeds = given;  // (a repeated one: refused as any grid value)
    grid->erase(grid->begin() + static_cast<std::ptrdiff_t>(i));
    plan->parameters.erase(std::find(plan->parameters.begin(), plan->parameters.end(), "seed"));
    return;
  }
}

// Reads the parts of the file; the overrides it names go to *swept (grid) or *listed (runs).
void ReadFile(StrictYaml& y, const YAML::Node& root, SweepPlan* plan,
              std::vector<std::string>* base_sets, std::vector<std::vector<SweptValue>>* grid,
              std::vector<std::vector<SweptValue>>* listed, std::vector<int64_t>* seeds) {
  if (y.Get(root, "sweep", "sweep", &plan->name, "a name", true) &&
      (plan->name.empty() || plan->name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") !=
                                 std::string::npos))
    y.Error(root["sweep"], "sweep", "a name is letters, digits, '_' and '-'");
  if (y.Get(root, "duration", "duration", &plan->duration_s, "a number of seconds", true) && !(plan->duration_s > 0))
    y.Error(root["duration"], "duration", "must be > 0");
  y.Get(root, "recorder", "recorder", &plan->recorder, "a component name");
  if (const YAML::Node set = root["set"]; set && y.Map(set, "set", {}))
    for (const auto& kv : set) base_sets->push_back(kv.first.Scalar() + "=" + tools::SetText(kv.second));
  const YAML::Node g = root["grid"], r = root["runs"];
  if (g && r) y.Error(root["runs"], "runs", "give grid or runs, not both");
  if (!g && !r) y.Error(root, "grid", "required key missing (or runs)");
  if (g) ReadGrid(y, g, "grid", "", &plan->parameters, grid);
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
          if (key == "seed") {
            y.Error(kv.second, where + ".seed", "the seeds are the sweep's: give seeds: [...] (each run once per seed)");
            continue;
          }
          if (std::find(plan->parameters.begin(), plan->parameters.end(), key) == plan->parameters.end())
            plan->parameters.push_back(key);
          listed->back().push_back({key, tools::SetText(kv.second), kv.second, where + "." + key});
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
  if (g) TakeGridSeeds(y, root, plan, grid, seeds);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The combinations: the grid's product (first key slowest), or the list as given.
std::vector<std::vector<const SweptValue*>> Combinations(const std::vector<std::vector<SweptValue>>& grid,
                                                      const std::vector<std::vector<SweptValue>>& listed) {
  std::vector<std::vector<const SweptValue*>> combos;
  if (grid.empty() && listed.empty()) return {{}};  // a grid of seeds only
  if (grid.empty()) {
    for (const auto& run : listed) {
      combos.emplace_back();
      for (const auto& o : run) combos.back().push_back(&o);
    }
    return combos;
  }
  combos.emplace_back();
  for (const auto& values : grid) {
    std::vector<std::vector<const SweptValue*>> next;
    for (const auto& combo : combos)
      for (const auto& v : values) {
        next.push_back(combo);
        next.back().push_back(&v);
      }
    combos = std::move(next);
  }
  return combos;
}

// The files of a data set folder, names and contents, in name order: its training's model
// changes when they do.
uint64_t HashFolder(const std::string& dir, uint64_t h) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec)) files.push_back(it->path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) h = tools::Fnv1a(ReadText(f.string()), tools::Fnv1a(fs::relative(f, dir, ec).string() + "\n", h));
  return h;
}

std::string Hex(uint64_t h) {
  char id[17];
  std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(h));
  return id;
}

// `dyad train`'s own verdict on `sets`: empty when it passes; else the data set's folder.
std::string CheckTraining(const std::string& config, const std::vector<std::string>& sets, std::string* dataset = nullptr) {
  auto c = pvrnn::LoadTrainConfig(config, sets);
  if (!c.ok()) return c.status().message();
  if (dataset) *dataset = c->dataset;
  return "";
}

// The trainings a train: section asks for (see the header); problems at the sweep file's lines.
void PlanTrainings(StrictYaml& y, const YAML::Node& t, const std::vector<std::string>& base,
                   const std::vector<std::vector<SweptValue>>& grid, SweepPlan* plan) {
  if (std::string why = CheckTraining(plan->train_config, base); !why.empty()) {
    y.Error(t["set"] ? t["set"] : t["config"], t["set"] ? "train.set" : "train.config", "does not train:\n" + why);
    return;
  }
  bool bad = false;
  for (const auto& values : grid)
    for (const auto& o : values) {
      std::vector<std::string> sets = base;
      sets.push_back(o.key + "=" + o.value);
      if (std::string why = CheckTraining(plan->train_config, sets); !why.empty()) {
        y.Error(o.node, o.where, "does not train:\n" + why);
        bad = true;
      }
    }
  if (bad) return;
  std::vector<std::vector<const SweptValue*>> combos = Combinations(grid, {});
  if (combos.empty()) combos.emplace_back();  // no grid: one model
  const uint64_t config_hash = tools::Fnv1a(ReadText(plan->train_config));
  for (const auto& combo : combos) {
    SweepTraining training;
    training.sets = base;
    for (const SweptValue* o : combo) {
      training.params.emplace_back("train." + o->key, o->value);
      training.sets.push_back(o->key + "=" + o->value);
    }
    std::string dataset;
    CheckTraining(plan->train_config, training.sets, &dataset);
    uint64_t h = HashFolder(dataset, config_hash);
    for (const auto& s : training.sets) h = tools::Fnv1a(s + "\n", h);
    training.id = Hex(tools::Fnv1a(DYAD_VERSION, h));
    plan->trainings.push_back(std::move(training));
  }
}

// `train.model` names a parameter the graph sets (COMPONENT.PARAM or COMPONENT.params.PARAM).
void CheckModelKey(StrictYaml& y, const YAML::Node& t, const std::string& graph_path, const std::vector<std::string>& base,
                   const SweepPlan& plan) {
  const YAML::Node at = t["model"] ? t["model"] : t;
  std::string key = plan.model_key;
  const size_t dot = key.find('.');
  if (dot == std::string::npos) return y.Error(at, "train.model", "want COMPONENT.PARAM, got '" + key + "'");
  const std::string component = key.substr(0, dot);
  std::string param = key.substr(dot + 1);
  if (param.rfind("params.", 0) == 0) param = param.substr(7);
  std::vector<dyad::Override> overrides;
  for (const auto& s : base) overrides.push_back({s});
  std::vector<Diagnostic> ignored;
  const Graph g = LoadGraph(graph_path, overrides, &ignored);
  for (const auto& c : g.components)
    if (c.name == component) {
      if (!c.params || !c.params.IsMap() || !c.params[param])
        y.Error(at, "train.model", "the graph's " + component + " has no parameter " + param + " to give the trained model to");
      return;
    }
  y.Error(at, "train.model", "the graph has no component " + component);
}

// Path parameters that name what a run writes, not what it reads: their content is no input.
bool WrittenByTheRun(const std::string& type, const std::string& param) {
  static const std::set<std::pair<std::string, std::string>> written = {
      {"recorder", "file"}, {"counter_sink", "file"}, {"learner", "out"}, {"web", "port_file"}, {"web", "token_file"}};
  return written.count({type, param}) > 0;
}

// What `path` names, as hex: a file's bytes, a folder's files (names and bytes), or its absence.
// Cached: a sweep's runs share their files.
const std::string& ContentHash(const std::string& path, std::map<std::string, std::string>* cache) {
  auto [it, added] = cache->emplace(path, "");
  if (!added) return it->second;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (fs::is_regular_file(st)) it->second = Hex(tools::Fnv1a(ReadText(path), tools::Fnv1a("file\n")));
  else if (fs::is_directory(st)) it->second = Hex(HashFolder(path, tools::Fnv1a("folder\n")));
  else it->second = "absent";
  return it->second;
}

// A run's cache key (see the header): the graph as run, the duration, and every file it reads.
class RunKey {
 public:
  RunKey(const SweepPlan& plan, const std::vector<std::string>& base, const std::vector<std::string>& plugins) : plan_(plan) {
    std::vector<Diagnostic> ignored;  // the graph validated with these before
    const Graph g = LoadGraph(plan.graph, Overrides(base), &ignored);
    // Their problems were the validation's (a plugin that does not load fails it).
    for (const auto& p : g.plugins) (void)catalog_.Load(p);
    for (const auto& p : plugins) (void)catalog_.Load(p);
    (void)catalog_.LoadDefault({});
    replaced_.insert(plan.recorder + ".file");  // each run's own recording
    if (!plan.trainings.empty()) {              // each run's trained model (its id counts instead)
      const std::string key = plan.model_key, param = key.substr(key.find('.') + 1);
      replaced_.insert(key.substr(0, key.find('.')) + "." + (param.rfind("params.", 0) == 0 ? param.substr(7) : param));
    }
  }

  uint64_t Hash(const std::vector<std::string>& sets) {
    std::vector<Diagnostic> ignored;
    const Graph g = LoadGraph(plan_.graph, Overrides(sets), &ignored);
    uint64_t h = tools::Fnv1a(g.yaml_text);  // every file it extends, merged, and the sets
    char duration[40];
    std::snprintf(duration, sizeof duration, "duration %.17g\n", plan_.duration_s);
    h = tools::Fnv1a(duration, h);
    const ResolvedGraph resolved = ValidateGraph(g, catalog_, &ignored);
    for (const ResolvedComponent& rc : resolved.components) {
      if (rc.config == nullptr || rc.entry == nullptr) continue;
      for (const ParamSpec& ps : rc.entry->spec.params()) {
        const std::string key = rc.config->name + "." + ps.name;
        if (!ps.path || WrittenByTheRun(rc.config->type, ps.name) || replaced_.count(key) || !rc.params.Has(ps.name)) continue;
        std::vector<std::string> paths;
        if (ps.type == ParamType::kStringList) paths = rc.params.StringList(ps.name);
        else paths.push_back(rc.params.String(ps.name));
        for (const std::string& p : paths)
          if (!p.empty()) h = tools::Fnv1a(key + " " + p + " " + ContentHash(p, &contents_) + "\n", h);
      }
    }
    return h;
  }

 private:
  static std::vector<Override> Overrides(const std::vector<std::string>& sets) {
    std::vector<Override> overrides;
    for (const auto& s : sets) overrides.push_back({s});
    return overrides;
  }
  const SweepPlan& plan_;
  Catalog catalog_;
  std::set<std::string> replaced_;  // COMPONENT.PARAM the sweep gives each run
  std::map<std::string, std::string> contents_;
};

}  // namespace

std::string ModelPath(const std::string& out, const SweepTraining& training) {
  return (fs::path(out) / "models" / (training.id + ".dpvrnn")).string();
}

SweepPlan LoadSweep(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems) {
  SweepPlan plan;
  plan.file = path;
  YAML::Node root;
  if (!tools::LoadYamlFile(path, "sweep", &root, problems)) return plan;
  StrictYaml y(StrictYaml::InFile(path, {}), problems);
  if (!y.Map(root, "", {"sweep", "graph", "study", "condition", "duration", "recorder", "set", "grid", "runs", "seeds", "train"}))
    return plan;
  std::vector<std::string> base, train_base;
  std::vector<std::vector<SweptValue>> grid, listed, train_grid;
  std::vector<int64_t> seeds;
  if (root["train"]) ReadTrain(y, root["train"], path, &plan, &train_base, &train_grid);
  ReadFile(y, root, &plan, &base, &grid, &listed, &seeds);
  ReadBase(y, root, path, plugins, &plan, &base, problems);
  if (!problems->empty()) return plan;

  // Hermetic and deterministic: stepped, and the recording where the sweep says.
  base.push_back("clock=stepped");
  base.push_back(plan.recorder + ".overwrite=true");
  // The trainings first: they do not depend on the graph validating (its own model, which every
  // run replaces, may not exist yet), and a typo in train: is then said whatever else is wrong.
  if (root["train"]) {
    CheckModelKey(y, root["train"], plan.graph, base, plan);
    PlanTrainings(y, root["train"], train_base, train_grid, &plan);
  }
  const std::string replaced = root["train"] ? tools::ValidatorKey(plan.model_key) : "";
  if (std::string why = tools::GraphProblems(plan.graph, base, plugins, replaced); !why.empty()) {
    y.Error(root["set"] ? root["set"] : root, root["set"] ? "set" : "graph", "the graph with these overrides does not validate:\n" + why);
    return plan;
  }
  std::set<std::string> checked;
  auto check = [&](const SweptValue& o) {
    if (!o.key.empty() && root["train"] && o.key == plan.model_key)
      return y.Error(o.node, o.where, "the sweep trains the models of " + plan.model_key + " (train.model): sweep one or the other");
    if (!checked.insert(o.key + "=" + o.value).second) return;
    std::vector<std::string> sets = base;
    sets.push_back(o.key + "=" + o.value);
    if (std::string why = tools::GraphProblems(plan.graph, sets, plugins, replaced); !why.empty()) y.Error(o.node, o.where, "does not validate:\n" + why);
  };
  for (const auto& values : grid)
    for (const auto& o : values) check(o);
  for (const auto& run : listed)
    for (const auto& o : run) check(o);
  if (!problems->empty()) return plan;

  const std::vector<std::vector<const SweptValue*>> combos = Combinations(grid, listed);
  RunKey key(plan, base, plugins);
  const int trainings = static_cast<int>(plan.trainings.size());
  for (int t = trainings > 0 ? 0 : -1; t < trainings; ++t)
    for (const auto& combo : combos)
      for (int64_t seed : seeds) {
        SweepRun run;
        run.seed = seed;
        run.sets = base;
        run.training = t;
        if (t >= 0) run.params = plan.trainings[static_cast<size_t>(t)].params;
        for (const SweptValue* o : combo) {
          run.params.emplace_back(o->key, o->value);
          run.sets.push_back(o->key + "=" + o->value);
        }
        run.sets.push_back("seed=" + std::to_string(seed));
        uint64_t h = key.Hash(run.sets);
        for (const auto& s : run.sets) h = tools::Fnv1a(s + "\n", h);
        if (t >= 0) h = tools::Fnv1a("model " + plan.trainings[static_cast<size_t>(t)].id + "\n", h);
        run.id = Hex(tools::Fnv1a(DYAD_VERSION, h));
        plan.runs.push_back(std::move(run));
      }
  return plan;
}

}  // namespace dyad::sweep
