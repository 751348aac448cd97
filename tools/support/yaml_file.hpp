// tools/support/yaml_file.hpp: what the tools' own YAML files (a sweep, a study) share.
//
// LoadYamlFile(path, what, &root, problems): the parsed file, or false with one problem: "cannot
// read the WHAT file" (at the path), or the parser's message at its line and column.
// SetText(node): a value as `dyad run --set KEY=VALUE` takes it: a scalar as written, anything
// else as flow YAML ("[1, 2]", "{lr: 0.1}").
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dyad/diagnostic.hpp"

namespace dyad::tools {

bool LoadYamlFile(const std::string& path, const std::string& what, YAML::Node* root, std::vector<Diagnostic>* problems);
std::string SetText(const YAML::Node& node);

}  // namespace dyad::tools
