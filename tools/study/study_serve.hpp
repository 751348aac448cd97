// tools/study/study_serve.hpp: `dyad study serve STUDY` (docs/study.md, "A study online"): one
// endpoint where every participant opens their private link (`dyad study links`) and does their
// session from their own browser: the consent page, their plan's trials in order (each a graph of
// the study run for them as `dyad study run` runs it, its subject's page relayed: online_front.hpp),
// then a completion code.
//
//   dyad study serve STUDY [--address 127.0.0.1] [--port 8443] [--tls-certificate PEM]
//                          [--max-sessions N] [--port-file F] [--origin URL]...
//
// Contract:
//   - Refused before anything listens (exit 2), each naming the file, key or flag: a study file
//     with problems; a graph without a subject's page to serve (one `web` component and a
//     `web_human`, the web component without its own token_file or TLS); consent_required
//     without online.consent; an address off loopback without --tls-certificate; a
//     --tls-certificate that is not a private PEM of a key and its certificate, valid now
//     (serve_certificate.hpp).
//   - GET /subject?token=T: the subject's page for a participant's token (front_admission.hpp:
//     404 for any other, 429 for an address guessing); WebSocket /subject/ws?token=T: the page's
//     socket (online_front.hpp). Pages from another origin than the front's own URLs, the links'
//     (DATA/links.csv, read at start) or --origin are refused by the web server.
//   - Prints where it listens and how many participants have links; with TLS, the names the
//     certificate is for and until when, and (without --origin) a warning for links to a host it
//     does not name or to http://; a line per page refused, trial started and trial ended.
//   - SIGINT or SIGTERM: every running trial is stopped as `dyad study run` stops it (its
//     outcome "stopped"; the participant repeats it when they come back), then it exits 0.
//     Killed (SIGKILL), the trials' graphs end by their parent-death signal; the log keeps a
//     start without its end, and the next `study serve` repeats that trial with its reason.
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace dyad::study {

struct ServeOptions {
  std::string file;
  std::string address = "127.0.0.1";
  int port = 8443;  // 0: any free one
  std::string tls_certificate, port_file;
  int max_sessions = 0;  // 0: the study file's online.max_sessions
  std::string domains;   // "FIRST-LAST" (--domains); empty: the study file's online.domains, else the graph's on
  std::vector<std::string> origins, plugins;
};

int Serve(const ServeOptions& o);
// The origins the pages are admitted from: --origin, the links' (`link_origins`, from
// DATA/links.csv) and the front's own URLs (each host of --address at --port; "HOST:0" for port
// 0, which the web server takes for the port it bound). One at its scheme's default port (https
// 443, http 80) is admitted with and without it: a browser's Origin leaves that port out.
std::vector<std::string> PageOrigins(const ServeOptions& o, const std::vector<std::string>& link_origins);
// Adds `serve` to `dyad study`.
void AddServeCommand(CLI::App* study, int& exit_code);

}  // namespace dyad::study
