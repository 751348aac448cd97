#include "dyad/ros2_names.hpp"

#include <cctype>

namespace dyad {

namespace {
// The DDS topic name's limit (Fast DDS and Cyclone both keep it to 255 characters; rcl checks the
// same after the "rt" prefix).
constexpr size_t kMaxDdsTopic = 255;

bool TokenChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
}  // namespace

std::string Ros2TopicNameProblem(std::string_view name) {
  if (name.empty()) return "must not be empty";
  if (name.front() != '/')
    return "must be fully qualified (start with '/'): dyad's components are not ROS nodes, there is no "
           "namespace to resolve a relative name against";
  if (name.size() == 1) return "must name a topic, not the root namespace '/'";
  if (name.back() == '/') return "must not end with '/'";
  for (size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '~') return "must not contain '~' (a private name needs a node)";
    if (c == '{' || c == '}') return "must not contain substitutions ('{...}')";
    if (c != '/' && !TokenChar(c))
      return std::string("may contain only letters, digits, '_' and '/', not '") + c + "'";
    if (c == '/' && i + 1 < name.size() && name[i + 1] == '/') return "must not contain repeated '/'";
    if (c == '_' && i + 1 < name.size() && name[i + 1] == '_') return "must not contain repeated '_'";
    if (c == '/' && i + 1 < name.size() && std::isdigit(static_cast<unsigned char>(name[i + 1])))
      return "a name token must not start with a digit ('" + std::string(name.substr(i + 1, name.find('/', i + 1) - i - 1)) + "')";
  }
  if (Ros2DdsTopic(name).size() > kMaxDdsTopic)
    return "is too long: its DDS topic (rt" + std::string(name.substr(0, 12)) + "...) would exceed " +
           std::to_string(kMaxDdsTopic) + " characters";
  return "";
}

std::string Ros2DdsTopic(std::string_view ros2_name) { return "rt" + std::string(ros2_name); }

std::string Ros2NameOfDdsTopic(std::string_view dds_topic) {
  if (dds_topic.size() < 4 || dds_topic.substr(0, 3) != "rt/") return "";
  return std::string(dds_topic.substr(2));
}

std::string Ros2TypeOfDdsType(std::string_view dds_type) {
  constexpr std::string_view kMiddle = "::msg::dds_::";
  const size_t m = dds_type.find(kMiddle);
  if (m == std::string_view::npos || m == 0 || dds_type.size() < m + kMiddle.size() + 2 || dds_type.back() != '_')
    return "";
  const std::string_view pkg = dds_type.substr(0, m);
  const std::string_view type = dds_type.substr(m + kMiddle.size(), dds_type.size() - m - kMiddle.size() - 1);
  if (pkg.find(':') != std::string_view::npos || type.find(':') != std::string_view::npos) return "";
  return std::string(pkg) + "/msg/" + std::string(type);
}

bool Ros2QosProfile(std::string_view name, Ros2Qos* qos) {
  // rmw/qos_profiles.h: default (reliable, volatile, keep last 10), sensor_data (best effort,
  // volatile, keep last 5), parameters and services_default (reliable, volatile, 1000 / 10).
  if (name == "default" || name == "services_default") *qos = Ros2Qos{true, 10};
  else if (name == "sensor_data") *qos = Ros2Qos{false, 5};
  else if (name == "parameters") *qos = Ros2Qos{true, 1000};
  else return false;
  return true;
}

std::vector<std::string> Ros2QosProfiles() { return {"default", "sensor_data", "services_default", "parameters"}; }

}  // namespace dyad
