// Fuzz target: graph loading and validation from YAML text (ParseGraph, then ValidateGraph
// against the catalog of this build's built-in plugins, as `dyad validate` does). Every problem
// must come back as a diagnostic naming the file: no exception, no abort.
#include <string>
#include <vector>

#include "dyad/graph.hpp"
#include "dyad/validate.hpp"
#include "fuzz_catalog.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<dyad::Diagnostic> diagnostics;
  dyad::Graph graph = dyad::ParseGraph(text, "fuzz.yaml", {}, &diagnostics);
  if (diagnostics.empty()) dyad::ValidateGraph(graph, dyad::fuzz::BuiltinCatalog(), &diagnostics);
  for (const dyad::Diagnostic& d : diagnostics) {
    const std::string line = d.ToString();
    dyad::fuzz::Require(line.rfind("fuzz.yaml", 0) == 0 && !d.message.empty(), "diagnostic without its file: " + line);
    dyad::fuzz::Require(!dyad::fuzz::IsLoaderFallback(d.message), "a yaml-cpp exception reached the loader's catch: " + line);
  }
  return 0;
}
