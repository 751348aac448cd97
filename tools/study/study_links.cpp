#include "study_links.hpp"

#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <vector>

#include "dyad/private_file.hpp"
#include "web_server.hpp"

namespace dyad::study {
namespace fs = std::filesystem;

Status CheckBaseUrl(const std::string& url) {
  const std::string key = "--base-url '" + url + "'";
  const bool https = url.rfind("https://", 0) == 0, http = url.rfind("http://", 0) == 0;
  if (!https && !http) return Status::InvalidArgument(key + ": must begin with https:// (the address participants open)");
  const std::string rest = url.substr(https ? 8 : 7);
  if (rest.empty() || rest[0] == '/') return Status::InvalidArgument(key + ": no host");
  if (std::any_of(url.begin(), url.end(), [](char c) { return c <= ' ' || c >= 127 || c == '"' || c == '\'' || c == ','; }) ||
      url.find_first_of("?#") != std::string::npos)
    return Status::InvalidArgument(key + ": a link's base has no query, fragment, space, quote or comma");
  const std::string host = rest.substr(0, rest.find('/'));
  const bool loopback =
      host == "localhost" || host.rfind("localhost:", 0) == 0 || host.rfind("127.0.0.1", 0) == 0 || host.rfind("[::1]", 0) == 0;
  if (http && !loopback)
    return Status::InvalidArgument(
        key + ": http:// only for a loopback host; participants' links must be https:// (their tokens cross the network)");
  return Status::OK();
}

StatusOr<std::string> ReadRoleToken(const std::string& path, const std::string& role, const std::string& holds) {
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return Status::Internal(path + ": vanished");
  if (S_ISLNK(st.st_mode) || !S_ISREG(st.st_mode))
    return Status::InvalidArgument(path + ": not a regular file (a link is refused)");
  if ((st.st_mode & 077) != 0)
    return Status::InvalidArgument(path + ": holds " + holds + " and is readable by others: chmod 600 it");
  std::ifstream in(path);
  const std::string key = role + " ";
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(key, 0) != 0) continue;
    const std::string token = line.substr(key.size());
    if (token.size() < 16 || token.size() > 256 || !std::all_of(token.begin(), token.end(), [](char c) {
          return c > ' ' && c < 127 && c != '&' && c != '#' && c != '+' && c != '%' && c != ',';
        }))
      return Status::InvalidArgument(path + ": the " + role + "'s token is not 16..256 characters fit for a link");
    return token;
  }
  return Status::InvalidArgument(path + ": no '" + role + " TOKEN' line");
}

StatusOr<std::string> ReadSubjectToken(const std::string& path) {
  return ReadRoleToken(path, "subject", "a participant's tokens");
}

StatusOr<Links> WriteLinks(const Study& s, const std::string& base_url) {
  if (Status b = CheckBaseUrl(base_url); !b.ok()) return b;
  std::string base = base_url;
  while (base.back() == '/') base.pop_back();
  if (s.token_file_webs.size() != 1)
    return Status::InvalidArgument(
        s.file +
        ": links need the graph's one web component without its own token_file (each participant gets their own); found " +
        std::to_string(s.token_file_webs.size()));
  const std::string web = s.token_file_webs[0];
  // Every existing file read before anything is written.
  std::vector<std::optional<std::string>> tokens;
  for (const std::string& p : s.participants) {
    const std::string file = (fs::path(s.data) / p / (web + "-tokens")).string();
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(file, ec))) {
      tokens.emplace_back();
      continue;
    }
    auto t = ReadSubjectToken(file);
    if (!t.ok()) return t.status();
    tokens.emplace_back(*t);
  }
  Links out;
  std::string csv = "participant,link\n";
  for (size_t i = 0; i < s.participants.size(); ++i) {
    const fs::path dir = fs::path(s.data) / s.participants[i];
    if (!tokens[i]) {
      if (Status d = CreatePrivateDirectories(dir.string()); !d.ok()) return d;
      tokens[i] = web::RandomToken();
      const std::string text =
          "experimenter " + web::RandomToken() + "\nsubject " + *tokens[i] + "\nviewer " + web::RandomToken() + "\n";
      if (Status w = WritePrivateFile((dir / (web + "-tokens")).string(), text, CreateMode::kNew); !w.ok()) return w;
      ++out.made;
    } else {
      ++out.kept;
    }
    csv += s.participants[i] + "," + base + "/subject?token=" + *tokens[i] + "\n";
  }
  out.csv = (fs::path(s.data) / "links.csv").string();
  if (Status c = CreatePrivateDirectories(s.data); !c.ok()) return c;
  if (Status w = WritePrivateFile(out.csv, csv, CreateMode::kReplace); !w.ok()) return w;
  return out;
}

std::vector<std::string> LinkOrigins(const Study& s) {
  std::vector<std::string> origins;
  std::ifstream in(fs::path(s.data) / "links.csv");
  std::string line;
  std::getline(in, line);  // participant,link
  while (std::getline(in, line)) {
    const std::string link = line.substr(line.find(',') + 1);
    const size_t scheme = link.find("://");
    if (line.find(',') == std::string::npos || scheme == std::string::npos) continue;
    const std::string origin = link.substr(0, link.find('/', scheme + 3));
    if (std::find(origins.begin(), origins.end(), origin) == origins.end()) origins.push_back(origin);
  }
  return origins;
}

void AddLinksCommand(CLI::App* study, int& exit_code) {
  struct Options {
    std::string file, base_url;
    std::vector<std::string> plugins;
  };
  auto o = std::make_shared<Options>();
  auto* links = study->add_subcommand(
      "links",
      "One private link per participant (their own token, kept in a 0600 file) and DATA/links.csv for a recruitment platform");
  links->add_option("study", o->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  links->add_option("--base-url", o->base_url, "The address participants open: https://HOST[:PORT][/PATH]")->required();
  links->add_option("--plugins", o->plugins, "Extra plugin file or folder (repeatable)");
  links->callback([o, &exit_code] {
    std::vector<Diagnostic> problems;
    const Study s = LoadStudy(o->file, o->plugins, &problems);
    for (const auto& p : problems) std::cerr << p.ToString() << "\n";
    if (!problems.empty()) {
      std::cerr << o->file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << "\n";
      exit_code = 2;
      return;
    }
    auto l = WriteLinks(s, o->base_url);
    if (!l.ok()) {
      std::cerr << "dyad study links: " << l.status().message() << "\n";
      exit_code = 2;
      return;
    }
    std::cout << "links: " << s.participants.size() << " participants (" << l->made << " new tokens, " << l->kept << " kept) -> "
              << l->csv << " (0600: every link opens a participant's session; give it to the recruitment platform only)\n";
    exit_code = 0;
  });
}

}  // namespace dyad::study
