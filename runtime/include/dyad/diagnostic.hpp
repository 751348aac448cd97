// dyad/diagnostic.hpp — a problem found in a YAML document, at the place that wrote it.
//
//   SourceMark{"g.yaml", 12, 5}.ToString()          "g.yaml:12:5"
//   SourceMark{"--set seed=-1", 0, 0}.ToString()    "--set seed=-1" (a value from the command line)
//   Diagnostic{mark, "seed", "must be ..."}         "g.yaml:12:5: seed: must be ..."
//
// No DDS: the graph, the training config and every other strict YAML format report with these
// (dyad/strict_yaml.hpp).
#pragma once

#include <string>

#include <yaml-cpp/yaml.h>

namespace dyad {

// A position in a source file (1-based); line 0 means "not from a file" (command line).
struct SourceMark {
  std::string file;
  int line = 0;
  int column = 0;
  std::string ToString() const;  // "file:line:col" or "file"
  // True for the position of a value given with --set (file "--set KEY=VALUE").
  bool FromCommandLine() const;
  // Where `node` starts in `file` (yaml-cpp counts from 0; we count from 1).
  static SourceMark Of(const std::string& file, const YAML::Node& node);
};

struct Diagnostic {
  SourceMark mark;
  std::string key;      // dotted path, e.g. "components.mixer.params.gain"
  std::string message;
  std::string ToString() const;  // "file:line:col: key: message" ("key = value: why" for "= value: why")
};

}  // namespace dyad
