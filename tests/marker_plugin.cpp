// A plugin whose loading leaves a trace: when loaded it creates the file named by the environment
// variable DYAD_TEST_PLUGIN_MARKER. Proves that `dyad validate --no-plugins` runs none of a
// graph's plugins (and, without the flag, that the same graph's plugin is run). Kept out of the
// plugin folder.
#include <cstdio>
#include <cstdlib>

#include <dyad/component.hpp>

namespace {
__attribute__((constructor)) void LeaveTrace() {
  if (const char* path = std::getenv("DYAD_TEST_PLUGIN_MARKER")) {
    if (std::FILE* f = std::fopen(path, "w")) std::fclose(f);
  }
}
}  // namespace

DYAD_PLUGIN(registry) { (void)registry; }
