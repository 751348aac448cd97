// A plugin built for another component ABI: the catalog must refuse it, naming both versions.
#include <cstdint>

namespace dyad { class PluginRegistry; }

extern "C" __attribute__((visibility("default"))) uint32_t dyad_plugin_abi_version() { return 999; }
extern "C" __attribute__((visibility("default"))) void dyad_plugin_register(dyad::PluginRegistry&) {}
