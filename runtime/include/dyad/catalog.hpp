// dyad/catalog.hpp — the component types available to a run, loaded from plugins.
//
// A plugin is a shared library exporting `dyad_plugin_abi_version` and `dyad_plugin_register`
// (write them with DYAD_PLUGIN, see component.hpp). The catalog dlopen()s plugin files, checks
// the ABI version, lets each register its types and describes each type once. Libraries stay
// loaded for the catalog's lifetime (components' code lives in them).
//
// Search order: explicit paths (the graph's `plugins:`), then DYAD_PLUGIN_PATH (':'-separated
// files or folders), then the built-in plugin folder of this build or installation. A folder
// contributes every `*.so` in it that exports the entry points. The first plugin to register
// a type name wins; a later one with the same name is reported as a conflict.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/status.hpp>

namespace dyad {

struct CatalogEntry {
  ComponentType type;
  ComponentSpec spec;
};

class Catalog {
 public:
  Catalog();
  ~Catalog();
  Catalog(const Catalog&) = delete;
  Catalog& operator=(const Catalog&) = delete;

  // Loads one plugin file or every plugin in a folder. Errors name the file.
  Status Load(const std::string& path);
  // Loads `paths`, then DYAD_PLUGIN_PATH, then the built-in folder. Returns every problem met
  // (missing paths, ABI mismatches, dlopen errors, duplicate type names), one per line.
  Status LoadDefault(const std::vector<std::string>& paths);

  // Registers the types of a plugin linked into this program (tests, programs embedding dyad):
  // `register_types` is what DYAD_PLUGIN would export; `origin` names it in messages. Same rules
  // as a loaded plugin (first registration of a name wins, conflicts reported).
  Status Register(const std::string& origin, void (*register_types)(PluginRegistry&));

  const CatalogEntry* Find(const std::string& type_name) const;
  const std::map<std::string, CatalogEntry>& entries() const { return entries_; }
  // Every message type seen on some component's port, by IDL name and by short name.
  const TypeInfo* FindMessageType(const std::string& name) const;
  // Sorted by name; built-in IDL types first known, then those of loaded plugins' ports.
  const std::vector<const TypeInfo*>& MessageTypes() const { return message_types_; }

  // The folder holding the built-in plugins of this build (or installation).
  static std::string BuiltinPluginDir();

 private:
  class Registry;
  Status LoadFile(const std::string& file);
  void AddMessageType(const TypeInfo* type);
  std::map<std::string, CatalogEntry> entries_;
  std::vector<void*> handles_;
  std::vector<std::string> loaded_files_;
  std::vector<const TypeInfo*> message_types_;
};

}  // namespace dyad
