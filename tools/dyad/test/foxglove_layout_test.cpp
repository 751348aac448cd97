// docs/foxglove/dyad.json, the Foxglove layout dyad ships: JSON Foxglove reads (configById and a
// layout tree of split panels), the panels the docs name, and every message path in it names a
// topic of configs/interactive.yaml and a field of that topic's IDL type: a renamed topic or
// field breaks this test, not the experimenter's screen.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "dyad/graph.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The fields of `type` (its short name) in idl/*.idl.
std::set<std::string> IdlFields(const std::string& type) {
  std::set<std::string> fields;
  for (const auto& f : fs::directory_iterator(fs::path(DYAD_SOURCE_DIR) / "idl")) {
    if (f.path().extension() != ".idl") continue;
    const std::string text = Slurp(f.path());
    const size_t at = text.find("struct " + type + " {");
    if (at == std::string::npos) continue;
    std::istringstream body(text.substr(at, text.find("};", at) - at));
    static const std::regex member(R"(^\s*[A-Za-z_:<> ]+\s([a-z_0-9]+);)");
    for (std::string line; std::getline(body, line);)
      if (std::smatch m; std::regex_search(line, m, member)) fields.insert(m[1]);
  }
  return fields;
}

void Leaves(const nlohmann::json& node, std::set<std::string>* out) {
  if (node.is_string()) {
    out->insert(node.get<std::string>());
    return;
  }
  ASSERT_TRUE(node.is_object()) << node.dump();
  EXPECT_TRUE(node.contains("direction") && (node["direction"] == "row" || node["direction"] == "column")) << node.dump();
  Leaves(node.at("first"), out);
  Leaves(node.at("second"), out);
}

TEST(FoxgloveLayout, EveryPanelIsPlacedAndEveryPathNamesATopicAndField) {
  const auto layout = nlohmann::json::parse(Slurp(fs::path(DYAD_SOURCE_DIR) / "docs" / "foxglove" / "dyad.json"));
  const auto& panels = layout.at("configById");
  for (const char* id : {"Plot!position-x", "Plot!position-y", "Plot!free-energy", "Plot!congruence", "Table!stats"})
    EXPECT_TRUE(panels.contains(id)) << id;
  std::set<std::string> placed;
  Leaves(layout.at("layout"), &placed);
  std::set<std::string> configured;
  for (const auto& [id, config] : panels.items()) configured.insert(id);
  EXPECT_EQ(placed, configured) << "a panel configured but not placed, or placed but not configured";

  std::vector<Diagnostic> problems;
  const Graph g = LoadGraph(std::string(DYAD_SOURCE_DIR) + "/configs/interactive.yaml", {}, &problems);
  ASSERT_TRUE(problems.empty());
  std::map<std::string, std::string> types = {{"dyad/stats", "ComponentStats"}};
  for (const auto& t : g.topics) types[t.name] = t.type;
  std::vector<std::string> paths;
  for (const auto& [id, config] : panels.items()) {
    for (const auto& p : config.value("paths", nlohmann::json::array())) paths.push_back(p.at("value"));
    if (config.contains("topicPath")) paths.push_back(config["topicPath"]);
  }
  ASSERT_GE(paths.size(), 10u);
  static const std::regex path(R"re(^"([^"]+)"(?:\.([a-z_0-9]+))?$)re");
  for (const auto& p : paths) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(p, m, path)) << "not a Foxglove message path of a quoted topic: " << p;
    ASSERT_TRUE(types.count(m[1])) << p << ": no topic " << m[1] << " in configs/interactive.yaml";
    if (m[2].matched) {
      EXPECT_TRUE(IdlFields(types[m[1]]).count(m[2])) << p << ": " << types[m[1]] << " has no field " << m[2];
    }
  }
}

}  // namespace
}  // namespace dyad::cli
