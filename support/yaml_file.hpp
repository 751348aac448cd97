// support/yaml_file.hpp: what the tools' own YAML files (a sweep, a study) share, and the quoting
// of a --set value (the learner component's too). Below the components (support/CMakeLists.txt);
// the namespace is dyad::tools, its first users'.
//
// LoadYamlFile(path, what, &root, problems): the parsed file, or false with one problem: "cannot
// read the WHAT file" (at the path), or the parser's message at its line and column.
// SetText(node): a value as `dyad run --set KEY=VALUE` takes it: a scalar as written, anything
// else as flow YAML ("[1, 2]", "{lr: 0.1}").
// PathBeside(file, path): a path written in `file`, absolute and normal (relative to the file's
// folder, as a graph's paths are).
// YamlQuoted(text): `text` as a YAML single-quoted scalar ('' is a quote inside it): a --set value
// that stays a string whatever it holds (" #", ": ", a leading '[').
// Fnv1a(text, h): a 64-bit hash stable across builds and machines (a sweep's run and model ids
// name folders; a study's blind labels must not change), chainable through `h`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dyad/diagnostic.hpp"

namespace dyad::tools {

bool LoadYamlFile(const std::string& path, const std::string& what, YAML::Node* root, std::vector<Diagnostic>* problems);
std::string SetText(const YAML::Node& node);
std::string YamlQuoted(const std::string& text);
std::string PathBeside(const std::string& file, const std::string& path);

inline uint64_t Fnv1a(const std::string& text, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

}  // namespace dyad::tools
