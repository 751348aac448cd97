// The YAML document a graph file stands for: the file merged over the files it `extends:`, with
// the command line's `--set`s written in. graph.cpp reads the Graph from it.
//
// Every part of the document remembers where it was written (`origins`: key path -> file, or
// "--set TEXT"), so a problem names that file's line or the --set, and a relative path is relative
// to the file that wrote it (Graph::MarkOf, Graph::FolderOf).
//
// Merging an overlay over its base: maps merge key by key; scalars and lists replace;
// `key: !reset` removes the key (a component, a param, a process); `key: !override {...}` takes
// the map as written instead of merging it (a driver's params when its type changes).
//
// Every `--set KEY=VALUE` is an edit of the document at KEY (VALUE parsed as YAML), checked later
// exactly like the file's own keys:
//   clock|seed|domain_id|graph|logs|plugins=V     the graph's own keys
//   network.KEY=V, security.KEY=V, topics.T.KEY=V a key of a section
//   processes.NAME.KEY=V                          a key of a process the file declares
//   C.type|rate_hz|trigger|process=V              a component's own keys
//   C.inputs.PORT=TOPIC, C.outputs.PORT=TOPIC     a binding
//   C.params.PARAM=V or C.PARAM=V                 a parameter
//   C.params={...}                                all of a component's parameters
#pragma once

#include <map>
#include <string>
#include <vector>

#include "dyad/graph.hpp"

namespace dyad {

struct GraphDocument {
  YAML::Node root;  // a mapping; not one (test IsMap()) when the file could not be read (diagnostics say why)
  std::map<std::string, std::string> origins;  // see Graph::origins
  std::vector<std::string> bases;              // the files extended, nearest first
  std::vector<std::string> sets;               // the --set texts written in
};

// Parses `yaml_text` (the file `path`) and the chain of files it extends, merged.
GraphDocument ReadGraphDocument(const std::string& yaml_text, const std::string& path,
                                std::vector<Diagnostic>* diagnostics);

// Writes each override into doc->root; a malformed one (no '=', an unknown component or process,
// a value that is not YAML) is reported and skipped.
void ApplySets(const std::vector<Override>& overrides, GraphDocument* doc, std::vector<Diagnostic>* diagnostics);

}  // namespace dyad
