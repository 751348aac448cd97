#include "dyad/human_input/events.hpp"

#include <yaml-cpp/yaml.h>

namespace dyad::human_input {
namespace {

std::string Span(const InterventionEvent& e) {
  return "steps " + std::to_string(e.start) + ".." + std::to_string(e.end - 1);
}

}  // namespace

StatusOr<std::vector<InterventionEvent>> ParseEvents(const std::string& yaml_text, int num_primitives) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("events: not valid YAML: " + e.msg);
  }
  if (root.IsNull()) return std::vector<InterventionEvent>{};
  if (!root.IsSequence()) return Status::InvalidArgument("events: must be a list of {start, end, primitive}");
  std::vector<InterventionEvent> out;
  for (size_t i = 0; i < root.size(); ++i) {
    const std::string at = "events[" + std::to_string(i) + "]";
    const YAML::Node n = root[i];
    if (!n.IsMap()) return Status::InvalidArgument(at + ": must be a map {start, end, primitive}");
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      if (key != "start" && key != "end" && key != "primitive")
        return Status::InvalidArgument(at + "." + key + ": unknown key (expected start, end, primitive)");
    }
    InterventionEvent e;
    auto integer = [&](const char* key, int64_t* v) -> Status {
      const YAML::Node k = n[key];
      if (!k) return Status::InvalidArgument(at + "." + key + ": missing");
      try {
        *v = k.as<int64_t>();
      } catch (const YAML::Exception&) {
        return Status::InvalidArgument(at + "." + key + " = " + YAML::Dump(k) + ": must be an integer");
      }
      return Status::OK();
    };
    int64_t primitive = 0;
    if (Status s = integer("start", &e.start); !s.ok()) return s;
    if (Status s = integer("end", &e.end); !s.ok()) return s;
    if (Status s = integer("primitive", &primitive); !s.ok()) return s;
    if (e.start < 0) return Status::InvalidArgument(at + ".start = " + std::to_string(e.start) + ": must be >= 0");
    if (e.end <= e.start)
      return Status::InvalidArgument(at + ".end = " + std::to_string(e.end) + ": must be > start (" +
                                     std::to_string(e.start) + ")");
    if (primitive < 0 || primitive >= num_primitives)
      return Status::InvalidArgument(at + ".primitive = " + std::to_string(primitive) + ": must be in 0.." +
                                     std::to_string(num_primitives - 1) + " (the data set has " +
                                     std::to_string(num_primitives) + " primitives)");
    e.primitive = static_cast<int>(primitive);
    if (!out.empty()) {
      const InterventionEvent& prev = out.back();
      const std::string prev_at = "events[" + std::to_string(i - 1) + "]";
      if (e.start < prev.start)
        return Status::InvalidArgument(at + ": starts at step " + std::to_string(e.start) + ", before " + prev_at +
                                       " (step " + std::to_string(prev.start) + "): list events in order");
      if (e.start < prev.end)
        return Status::InvalidArgument(at + ": " + Span(e) + " overlap " + prev_at + " (" + Span(prev) + ")");
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace dyad::human_input
