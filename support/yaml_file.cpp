#include "yaml_file.hpp"

#include <filesystem>

namespace dyad::tools {

bool LoadYamlFile(const std::string& path, const std::string& what, YAML::Node* root, std::vector<Diagnostic>* problems) {
  try {
    *root = YAML::LoadFile(path);
    return true;
  } catch (const YAML::BadFile&) {
    problems->push_back({SourceMark{path, 0, 0}, "", "cannot read the " + what + " file"});
  } catch (const YAML::Exception& e) {
    problems->push_back({SourceMark{path, e.mark.line + 1, e.mark.column + 1}, "", e.msg});
  }
  return false;
}

std::string SetText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << node;
  return e.c_str();
}

std::string YamlQuoted(const std::string& text) {
  std::string q = "'";
  for (char ch : text) q += ch == '\'' ? std::string("''") : std::string(1, ch);
  return q + "'";
}

std::string PathBeside(const std::string& file, const std::string& path) {
  std::filesystem::path p(path);
  // absolute(file) first: a bare "s.yaml" has an empty parent, which absolute() refuses.
  if (p.is_relative()) p = std::filesystem::absolute(file).parent_path() / p;
  return p.lexically_normal().string();
}

}  // namespace dyad::tools
