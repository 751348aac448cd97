// tools/study/study_links.hpp: `dyad study links STUDY --base-url URL` (docs/study.md, "Links for a
// study online"): one private link per participant, in a CSV a recruitment platform takes.
//
// Contract of WriteLinks:
//   - A participant's link carries their subject token, kept where `dyad study run` keeps it:
//     the token file of the graph's web component, DATA/<participant>/<web>-tokens (0600, one
//     "ROLE TOKEN" line for each of experimenter, subject and viewer, as the web component reads
//     it). A missing file is made with new tokens (its folder 0700); an existing one is read and
//     never changed, so a link once sent stays valid, and a lab session of that participant uses
//     the same token.
//   - DATA/links.csv (0600, replaced whole): "participant,link", then one row per participant in
//     the study file's order, the link BASE_URL/subject?token=TOKEN.
//   - The base URL (CheckBaseUrl): https://HOST[:PORT][/PATH], or http:// for a loopback host
//     (127.0.0.1, localhost, [::1]) only; no query, fragment, space, quote or comma; a trailing
//     '/' is dropped.
//   - Refused before anything is written: a graph without exactly one web component to give
//     per-participant tokens (Study::token_file_webs: a web component without its own
//     token_file); an existing token file that is a link, not a regular file, readable by others,
//     or without a usable subject token. The error names the file.
#pragma once

#include <string>
#include <vector>

#include "dyad/status.hpp"
#include "study_file.hpp"

namespace CLI {
class App;
}

namespace dyad::study {

struct Links {
  std::string csv;  // the CSV written
  int made = 0;     // token files made now
  int kept = 0;     // token files that existed
};

// The subject token of an existing token file (the web component's format), or why not (the
// refusals above, naming the file). `dyad study serve` reads the participants' tokens with it.
StatusOr<std::string> ReadSubjectToken(const std::string& path);
// The token of `role` ("experimenter", "subject", "viewer") in a file of "ROLE TOKEN" lines, with
// the same refusals; `holds` says what the file holds ("a participant's tokens").
StatusOr<std::string> ReadRoleToken(const std::string& path, const std::string& role, const std::string& holds);

Status CheckBaseUrl(const std::string& url);
StatusOr<Links> WriteLinks(const Study& s, const std::string& base_url);
// The origins (scheme://host[:port]) of the links in DATA/links.csv, each once, in the file's
// order: where participants open their pages (`dyad study serve` admits them). None without the file.
std::vector<std::string> LinkOrigins(const Study& s);

// Adds `links` to `dyad study`.
void AddLinksCommand(CLI::App* study, int& exit_code);

}  // namespace dyad::study
