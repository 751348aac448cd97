#include "hosts/watcher_join.hpp"

#include <chrono>
#include <ostream>
#include <thread>

#include "graph/run_partition.hpp"

namespace dyad {

std::unique_ptr<DdsParticipant> JoinAsWatcher(const IntrospectOptions& o, const std::string& name, std::ostream& err) {
  DdsParticipant::Options po;
  po.scope = DdsParticipant::Scope::kWatcher;
  po.network = o.network;
  po.security = o.security;
  po.partitions = {o.run_id.empty() || o.graph_name.empty() ? WatchPartition(o.graph_name) : RunPartition(o.graph_name, o.run_id)};
  auto p = DdsParticipant::Create(o.domain_id, name, std::move(po));
  if (!p.ok()) {
    err << p.status().message() << "\n";
    return nullptr;
  }
  return std::move(p.value());
}

std::string DiscoverType(DdsParticipant& p, const std::string& topic, double wait_s, const InterruptWatcher& interrupt) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while (std::chrono::steady_clock::now() < end && !interrupt.interrupted()) {
    for (const auto& e : p.Discovered())
      if (e.writer && e.topic == topic) return e.type;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return "";
}

const TypeInfo* ResolveType(const Catalog& catalog, const std::string& dds_type, const std::string& topic, std::ostream& err) {
  for (const TypeInfo* t : catalog.MessageTypes()) {
    if (t->dds_name() == dds_type) return t;
  }
  const std::string base = dds_type.substr(0, dds_type.find('#'));
  for (const TypeInfo* t : catalog.MessageTypes())
    if (t->name == base) {
      err << "topic '" << topic << "' carries " << dds_type << " but this dyad knows " << t->dds_name()
          << " (same IDL name, different definition): rebuild from the same idl/\n";
      return nullptr;
    }
  err << "topic '" << topic << "' carries " << dds_type
      << ", a type this dyad does not know: name the plugin that defines it (--graph GRAPH.yaml, --plugins FILE,"
         " or DYAD_PLUGIN_PATH)\n";
  return nullptr;
}

}  // namespace dyad
