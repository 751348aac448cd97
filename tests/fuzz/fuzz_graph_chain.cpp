// Fuzz target: a graph file with its `extends:` chain and the command line's --sets, loaded and
// validated as `dyad validate FILE --set ...` does (ReadGraphDocument's merge, ApplySets, the
// reader, ValidateGraph against the built-in plugins). YAML bytes x --set strings x extends:
// chains: the input is sections split at lines starting "#@@" (a YAML comment: a plain graph is
// one section):
//   section 0           the graph file, <dir>/fuzz.yaml
//   section i (1..5)    a file it may extend, <dir>/b<i>.yaml (its `extends: b2.yaml` chains on)
//   a section "#@@set"  then one --set per line (8 at most)
// Every problem must come back as a diagnostic that names a file of the chain (or the --set):
// no exception, no abort.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dyad/graph.hpp"
#include "dyad/validate.hpp"
#include "fuzz_catalog.hpp"
#include "fuzz_support.hpp"

namespace {

constexpr size_t kMaxBases = 5, kMaxSets = 8;

std::string FolderName() {
  const char* tmp = std::getenv("TMPDIR");
  return std::string(tmp && *tmp ? tmp : "/tmp") + "/dyad_fuzz_chain_" + std::to_string(getpid());
}

void RemoveFolder() {
  std::error_code ec;
  std::filesystem::remove_all(FolderName(), ec);
}

// This process's folder of chain files (one per process: fuzzing jobs run side by side), removed
// at exit.
const std::string& Folder() {
  static const std::string dir = [] {
    const std::string d = FolderName();
    std::filesystem::create_directories(d);
    std::atexit(RemoveFolder);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::vector<std::string_view> sections = dyad::fuzz::Split(input, "\n#@@");
  const std::string dir = Folder();
  std::vector<dyad::Override> overrides;
  size_t bases = 0;
  for (size_t i = 1; i < sections.size(); ++i) {
    std::string_view s = sections[i];
    if (s.rfind("set", 0) == 0) {
      for (std::string_view line : dyad::fuzz::Split(s.substr(3), "\n"))
        if (!line.empty() && overrides.size() < kMaxSets) overrides.push_back({std::string(line)});
    } else if (bases < kMaxBases) {
      std::ofstream(dir + "/b" + std::to_string(++bases) + ".yaml", std::ios::binary | std::ios::trunc)
          .write(s.data(), static_cast<std::streamsize>(s.size()));
    }
  }
  // A base the previous input wrote and this one does not: gone, so each input reads only its own.
  for (size_t i = bases + 1; i <= kMaxBases; ++i) std::filesystem::remove(dir + "/b" + std::to_string(i) + ".yaml");

  std::vector<dyad::Diagnostic> diagnostics;
  const std::string path = dir + "/fuzz.yaml";
  dyad::Graph graph = dyad::ParseGraph(std::string(sections[0]), path, overrides, &diagnostics);
  if (diagnostics.empty()) dyad::ValidateGraph(graph, dyad::fuzz::BuiltinCatalog(), &diagnostics);
  for (const dyad::Diagnostic& d : diagnostics) {
    const std::string line = d.ToString();
    // The file that wrote the key: the graph, a file of its chain (an absolute path: what an
    // `extends:` names is resolved beside the file naming it, in `dir`), or the --set.
    const bool named = !d.mark.file.empty() && (d.mark.file[0] == '/' || d.mark.file.rfind("--set ", 0) == 0);
    dyad::fuzz::Require(named && !d.message.empty(), "diagnostic without its file: " + line);
    dyad::fuzz::Require(!dyad::fuzz::IsLoaderFallback(d.message), "a yaml-cpp exception reached the loader's catch: " + line);
  }
  return 0;
}
