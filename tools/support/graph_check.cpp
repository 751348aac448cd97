#include "graph_check.hpp"

#include <sstream>

#include "dyad/graph.hpp"
#include "dyad/run.hpp"

namespace dyad::tools {

std::string GraphProblems(const std::string& graph, const std::vector<std::string>& sets, const std::vector<std::string>& plugins,
                          const std::string& replaced) {
  std::vector<dyad::Override> overrides;
  for (const auto& s : sets) overrides.push_back({s});
  std::ostringstream out, err;
  if (ValidateGraphFile(graph, overrides, plugins, out, err) == 0) return "";
  std::string text;
  std::istringstream lines(err.str());
  for (std::string line; std::getline(lines, line);) {
    if (line.find("nothing was started") != std::string::npos) continue;
    if (!replaced.empty() && line.find(": " + replaced + ": ") != std::string::npos) continue;
    text += (text.empty() ? "" : "\n") + line;
  }
  if (!replaced.empty()) return text;
  return text.empty() ? "the graph does not validate" : text;
}

std::string ValidatorKey(const std::string& key) {
  const size_t dot = key.find('.');
  if (dot == std::string::npos) return key;
  const std::string param = key.substr(dot + 1);
  return "components." + key.substr(0, dot) + ".params." + (param.rfind("params.", 0) == 0 ? param.substr(7) : param);
}

}  // namespace dyad::tools
