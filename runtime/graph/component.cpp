// Out-of-line parts of the component API (compiled into the runtime library).
#include "dyad/component.hpp"

#include <dyad/on_demand_subscription.hpp>
#include <dyad/run_stopping.hpp>

#include <cstdio>
#include <cstdlib>

namespace dyad {

std::string TypeInfo::short_name() const {
  if (ros2()) return ros2_name;
  const auto pos = name.rfind("::");
  return pos == std::string::npos ? name : name.substr(pos + 2);
}

const std::string& Context::graph_name() const {
  static const std::string empty;
  return empty;
}
const std::string& Context::graph_yaml() const {
  static const std::string empty;
  return empty;
}
const std::string& Context::graph_folder() const {
  static const std::string empty;
  return empty;
}
const std::vector<TopicInfo>& Context::graph_topics() const {
  static const std::vector<TopicInfo> none;
  return none;
}
Status Context::SubscribeSerialized(const std::string& topic, SerializedCallback) {
  return Status::Unimplemented("SubscribeSerialized('" + topic + "'): this context has no DDS topics");
}
StatusOr<SerializedWriter*> Context::AdvertiseSerialized(const std::string& topic, const TypeInfo&) {
  return Status::Unimplemented("AdvertiseSerialized('" + topic + "'): this context has no DDS topics");
}

StatusOr<OnDemandSubscription*> SubscribeSerializedOnDemand(Context& ctx, const std::string& topic,
                                                            SerializedCallback callback) {
  auto* ext = dynamic_cast<detail::ContextExtensions*>(&ctx);
  if (ext == nullptr) return Status::Unimplemented("SubscribeSerializedOnDemand('" + topic + "'): this context has no DDS topics");
  return ext->SubscribeSerializedOnDemand(topic, std::move(callback));
}

bool RunStopping(const Context& ctx) {
  const auto* query = dynamic_cast<const detail::RunStoppingQuery*>(&ctx);
  return query != nullptr && query->run_stopping();
}

ParamSpec& ComponentSpec::AddParam(std::string name, ParamType type, std::optional<ParamValue> default_value) {
  if (FindParam(name) != nullptr) {
    std::fprintf(stderr, "dyad: parameter '%s' declared twice\n", name.c_str());
    std::abort();
  }
  ParamSpec p;
  p.name = std::move(name);
  p.type = type;
  p.default_value = std::move(default_value);
  params_.push_back(std::move(p));
  return params_.back();
}

ParamSpec& ComponentSpec::RequiredParam(std::string name, ParamType type) { return AddParam(std::move(name), type, std::nullopt); }

ParamSpec& ComponentSpec::YamlParam(std::string name, std::string default_yaml) {
  return AddParam(std::move(name), ParamType::kYaml, std::move(default_yaml));
}

PortSpec& ComponentSpec::AddPort(std::vector<PortSpec>& ports, std::string name, const TypeInfo* type) {
  for (const auto& p : ports)
    if (p.name == name) {
      std::fprintf(stderr, "dyad: port '%s' declared twice\n", name.c_str());
      std::abort();
    }
  PortSpec p;
  p.name = std::move(name);
  p.type = type;
  ports.push_back(std::move(p));
  return ports.back();
}

const ParamSpec* ComponentSpec::FindParam(std::string_view name) const {
  for (const auto& p : params_)
    if (p.name == name) return &p;
  return nullptr;
}
const PortSpec* ComponentSpec::FindInput(std::string_view name) const {
  for (const auto& p : inputs_)
    if (p.name == name) return &p;
  return nullptr;
}
const PortSpec* ComponentSpec::FindOutput(std::string_view name) const {
  for (const auto& p : outputs_)
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace dyad
