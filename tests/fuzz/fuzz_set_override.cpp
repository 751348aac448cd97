// Fuzz target: the `--set NAME.PARAM=VALUE` override parser, applied to the demo graph
// (configs/demo.yaml) and validated as `dyad run --set ...` does. Each input line is one --set.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/graph.hpp"
#include "dyad/validate.hpp"
#include "fuzz_catalog.hpp"
#include "fuzz_support.hpp"

namespace {

const std::string& BaseGraph() {
  static const std::string text = [] {
    std::ifstream in(DYAD_FUZZ_BASE_GRAPH);
    std::stringstream s;
    s << in.rdbuf();
    dyad::fuzz::Require(!s.str().empty(), "cannot read " DYAD_FUZZ_BASE_GRAPH);
    return s.str();
  }();
  return text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<dyad::Override> overrides;
  for (std::string_view line : dyad::fuzz::Split(input, "\n")) {
    if (overrides.size() == 8) break;
    overrides.push_back({std::string(line)});
  }
  std::vector<dyad::Diagnostic> diagnostics;
  dyad::Graph graph = dyad::ParseGraph(BaseGraph(), "demo.yaml", overrides, &diagnostics);
  if (diagnostics.empty()) dyad::ValidateGraph(graph, dyad::fuzz::BuiltinCatalog(), &diagnostics);
  for (const dyad::Diagnostic& d : diagnostics) {
    dyad::fuzz::Require(!d.message.empty() && !d.ToString().empty(), "empty diagnostic");
    dyad::fuzz::Require(!dyad::fuzz::IsLoaderFallback(d.message), "a yaml-cpp exception reached the loader's catch: " + d.ToString());
  }
  return 0;
}
