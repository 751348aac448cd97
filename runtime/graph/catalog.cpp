// Plugin loading: dlopen, ABI check, registration, one description per type.
#include "dyad/catalog.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <dyad/msg/ros2_types.hpp>
#include <dyad/msg/types.hpp>

namespace fs = std::filesystem;

namespace dyad {

class Catalog::Registry final : public PluginRegistry {
 public:
  explicit Registry(std::string file) : file_(std::move(file)) {}
  void AddType(ComponentType type) override {
    type.plugin_path = file_;
    types.push_back(std::move(type));
  }
  std::vector<ComponentType> types;

 private:
  std::string file_;
};

Catalog::Catalog() {
  for (const TypeInfo* t : msg::AllTypes()) AddMessageType(t);
  for (const TypeInfo* t : ros2::AllTypes()) AddMessageType(t);
}

Catalog::~Catalog() {
  // Entries hold function pointers into the libraries: drop them first. Libraries are not
  // dlclose()d: component objects destroyed later may still run code from them, and unloading
  // buys nothing in a process that ends after the run.
  entries_.clear();
}

Status Catalog::LoadFile(const std::string& file) {
  const std::string canonical = fs::weakly_canonical(file).string();
  if (std::find(loaded_files_.begin(), loaded_files_.end(), canonical) != loaded_files_.end()) return Status::OK();
  void* handle = dlopen(canonical.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) return Status::IOError(file + ": cannot load plugin: " + dlerror());
  using AbiFn = uint32_t (*)();
  using RegisterFn = void (*)(PluginRegistry&);
  auto abi = reinterpret_cast<AbiFn>(dlsym(handle, "dyad_plugin_abi_version"));
  auto reg = reinterpret_cast<RegisterFn>(dlsym(handle, "dyad_plugin_register"));
  if (abi == nullptr || reg == nullptr) {
    dlclose(handle);
    return Status::InvalidArgument(file + ": not a dyad plugin (no DYAD_PLUGIN entry point)");
  }
  if (abi() != kPluginAbiVersion) {
    const uint32_t theirs = abi();
    dlclose(handle);
    return Status::FailedPrecondition(file + ": plugin built for component ABI " + std::to_string(theirs) +
                                      ", this dyad has ABI " + std::to_string(kPluginAbiVersion) + ": rebuild the plugin");
  }
  handles_.push_back(handle);
  loaded_files_.push_back(canonical);
  return Register(canonical, reg);
}

Status Catalog::Register(const std::string& origin, void (*register_types)(PluginRegistry&)) {
  const std::string& file = origin;
  Registry registry(origin);
  register_types(registry);
  std::ostringstream conflicts;
  for (auto& t : registry.types) {
    auto it = entries_.find(t.name);
    if (it != entries_.end()) {
      conflicts << file << ": component type '" << t.name << "' is already registered by " << it->second.type.plugin_path
                << " (keeping the first)\n";
      continue;
    }
    CatalogEntry e;
    e.type = t;
    t.describe(e.spec);
    bool bad_spec = false;
    for (const ParamSpec& p : e.spec.params()) {
      if (p.path && p.type != ParamType::kString && p.type != ParamType::kStringList) {
        conflicts << file << ": component type '" << t.name << "': param '" << p.name << "' is marked Path() but is "
                  << ToString(p.type) << " (only string and list of strings can be paths)\n";
        bad_spec = true;
      }
      if (p.live && (p.secret || p.type == ParamType::kYaml)) {
        conflicts << file << ": component type '" << t.name << "': param '" << p.name << "' is marked Live() but is "
                  << (p.secret ? "a secret" : "yaml") << " (those are read once, in Configure)\n";
        bad_spec = true;
      }
      if (p.secret && p.type != ParamType::kString) {
        conflicts << file << ": component type '" << t.name << "': param '" << p.name << "' is marked Secret() but is "
                  << ToString(p.type) << " (only a string can be a secret)\n";
        bad_spec = true;
      }
    }
    if (bad_spec) continue;
    for (const auto& p : e.spec.inputs()) AddMessageType(p.type);
    for (const auto& p : e.spec.outputs()) AddMessageType(p.type);
    entries_.emplace(t.name, std::move(e));
  }
  std::string c = conflicts.str();
  if (!c.empty()) {
    c.pop_back();
    return Status::InvalidArgument(c);
  }
  return Status::OK();
}

Status Catalog::Load(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(path, ec))
      if (e.path().extension() == ".so") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    std::string errors;
    for (const auto& f : files) {
      Status s = LoadFile(f);
      if (!s.ok()) errors += (errors.empty() ? "" : "\n") + s.message();
    }
    return errors.empty() ? Status::OK() : Status::InvalidArgument(errors);
  }
  if (!fs::exists(path, ec)) return Status::NotFound(path + ": no such plugin file or folder");
  return LoadFile(path);
}

Status Catalog::LoadDefault(const std::vector<std::string>& paths) {
  std::vector<std::string> all = paths;
  if (const char* env = std::getenv("DYAD_PLUGIN_PATH")) {
    std::stringstream ss(env);
    std::string item;
    while (std::getline(ss, item, ':'))
      if (!item.empty()) all.push_back(item);
  }
  const std::string builtin = BuiltinPluginDir();
  if (!builtin.empty()) all.push_back(builtin);
  std::string errors;
  for (const auto& p : all) {
    Status s = Load(p);
    if (!s.ok()) errors += (errors.empty() ? "" : "\n") + s.message();
  }
  return errors.empty() ? Status::OK() : Status::InvalidArgument(errors);
}

const CatalogEntry* Catalog::Find(const std::string& type_name) const {
  auto it = entries_.find(type_name);
  return it == entries_.end() ? nullptr : &it->second;
}

void Catalog::AddMessageType(const TypeInfo* type) {
  for (const TypeInfo* t : message_types_)
    if (t->name == type->name) return;
  message_types_.insert(std::upper_bound(message_types_.begin(), message_types_.end(), type,
                                         [](const TypeInfo* a, const TypeInfo* b) { return a->name < b->name; }),
                        type);
}

const TypeInfo* Catalog::FindMessageType(const std::string& name) const {
  for (const TypeInfo* t : MessageTypes())
    if (t->name == name || t->short_name() == name || t->dds_name() == name || (t->ros2() && t->ros2_name == name))
      return t;
  return nullptr;
}

std::string Catalog::BuiltinPluginDir() {
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&Catalog::BuiltinPluginDir), &info) == 0 || info.dli_fname == nullptr) return "";
  const fs::path lib_dir = fs::path(info.dli_fname).parent_path();
  std::error_code ec;
  for (const fs::path& candidate : {lib_dir / "dyad" / "plugins", lib_dir.parent_path() / "plugins"})
    if (fs::is_directory(candidate, ec)) return candidate.string();
  return "";
}

}  // namespace dyad
