#include <dyad/keystore_graph.hpp>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace dyad {

StatusOr<std::string> ReadKeystoreGraph(const std::string& keystore) {
  const std::string path = (std::filesystem::path(keystore) / kKeystoreGraphFile).string();
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return std::string();
  const std::string made = " (written by `dyad security init`: the graph this keystore is for)";
  if (S_ISLNK(st.st_mode)) return Status::InvalidArgument(path + ": a symbolic link (refused: it may point anywhere)" + made);
  if (!S_ISREG(st.st_mode)) return Status::InvalidArgument(path + ": not a regular file" + made);
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) return Status::IOError(path + ": cannot be read" + made);
  std::string name = text.str();
  if (!name.empty() && name.back() == '\n') name.pop_back();
  if (name.empty() || name.find_first_of("\n\r") != std::string::npos)
    return Status::InvalidArgument(path + ": not one graph name on one line" + made);
  return name;
}

Status CheckKeystoreGraph(const Graph& graph, const std::string& keystore) {
  auto owner = ReadKeystoreGraph(keystore);
  if (!owner.ok()) return owner.status();
  if (owner.value().empty() || owner.value() == graph.name) return Status::OK();
  return Status::FailedPrecondition(
      "keystore " + keystore + " was made for graph '" + owner.value() + "' (" +
      (std::filesystem::path(keystore) / kKeystoreGraphFile).string() + "), not for graph '" + graph.name + "' (" + graph.file +
      "): a keystore serves one graph (its CA admits every identity it issued, and the permissions do not name the "
      "graph, so one graph's identities could publish into the other's). Make a keystore per graph: `dyad security init "
      "NEW_DIR --graph " +
      graph.file + "`, and name NEW_DIR in its security.keystore");
}

}  // namespace dyad
