#include "study_serve.hpp"

#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string_view>
#include <thread>
#include <utility>

#include "dyad/private_file.hpp"
#include "front_admission.hpp"
#include "online_front.hpp"
#include "overview_channel.hpp"
#include "pages.hpp"
#include "run_process.hpp"
#include "serve_certificate.hpp"
#include "study_file.hpp"
#include "study_links.hpp"
#include "web_server.hpp"

namespace dyad::study {
extern const char* const kOverviewHtml;  // overview.html, embedded at configure time
namespace {

std::atomic<int> g_quit{0};  // lock-free: set by the handler, read by the loop
static_assert(std::atomic<int>::is_always_lock_free);
// The first SIGINT or SIGTERM stops the serve: its trials stopped as `dyad study run` stops them,
// waited for. A second one (a graph that does not end) exits at once, saying so: each trial's
// graph then gets its parent-death SIGINT, and its attempt stays unended in the log (repeated
// with that reason when the participant comes back).
extern "C" void OnServeSignal(int) {
  if (g_quit.fetch_add(1) == 0) return;
  static constexpr char kNow[] =
      "dyad study serve: a second stop: exiting now, without waiting for the trials' graphs (each gets SIGINT as its "
      "parent ends; their attempts stay unended in the session logs)\n";
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kNow, sizeof kNow - 1);
  ::_exit(130);
}

// Why the study cannot be served ("" when it can): each names its key or flag.
std::string WhyNotServed(const Study& s, const ServeOptions& o) {
  if (s.subject_web.empty())
    return s.file + ": graph: " + s.graph +
           " has no subject's page to serve: one `web` component (without its own token_file or TLS) and a `web_human`, as "
           "configs/interactive.yaml";
  if (s.consent_required && s.online.consent.empty())
    return s.file + ": online.consent: required to serve a study with consent_required (the consent page's text, a file)";
  if (!web::IsLoopback(o.address) && o.tls_certificate.empty())
    return "--tls-certificate: required off loopback (--address " + o.address +
           "): participants' tokens cross the network (dyad security init makes one, or give your own PEM)";
  return "";
}

// The host of an origin "scheme://host[:port]" ("[::1]" with its brackets).
std::string OriginHost(const std::string& origin) {
  const std::string rest = origin.substr(origin.find("://") + 3);
  return rest.substr(0, rest[0] == '[' ? rest.find(']') + 1 : rest.find(':'));
}

// With --tls-certificate: the certificate checked (refused: why, naming the flag), then what to
// print about it: the names it is for, and a warning for each links' origin (DATA/links.csv) a
// browser would refuse it at. Not with --origin: then a proxy's own certificate may be the one
// participants' browsers see.
StatusOr<std::string> TlsLines(const Study& s, const ServeOptions& o, const std::vector<std::string>& link_origins) {
  if (o.tls_certificate.empty()) return std::string();
  auto cert = ReadServeCertificate(o.tls_certificate, std::time(nullptr));
  if (!cert.ok()) return cert.status();
  std::string names, lines;
  for (const std::string& n : cert->names()) names += (names.empty() ? "" : ", ") + n;
  lines = "TLS: " + o.tls_certificate + ", a certificate for " + names + ", valid until " + cert->not_after() + "\n";
  const std::string links = s.data + "/links.csv";
  for (const std::string& origin : o.origins.empty() ? link_origins : std::vector<std::string>{}) {
    if (origin.rfind("https://", 0) != 0)
      lines += "warning: " + links + " has links to " + origin +
               ", plain HTTP, which this TLS port does not answer (dyad study links " + s.file + " --base-url https://...)\n";
    else if (!cert->Names(OriginHost(origin)))
      lines += "warning: " + links + " has links to " + origin +
               ", which the certificate does not name: a browser opening them here refuses it " +
               "(dyad security init --web-host " + OriginHost(origin) +
               " issues one; behind a proxy with its own certificate, give --origin)\n";
  }
  return lines;
}

web::WebServer::Options ServerOptions(const ServeOptions& o, const std::vector<std::string>& link_origins,
                                      FrontAdmission* admission, OnlineFront* front, OverviewChannel* overview,
                                      int max_sessions) {
  web::WebServer::Options so;
  so.address = o.address;
  so.port = o.port;
  so.tls_certificate = o.tls_certificate;
  so.admit = [admission](std::string_view token, std::string_view remote) {
    return admission->Admit(token, remote, FrontAdmission::Clock::now());
  };
  so.pages["/subject"] = web::WebServer::Page{"text/html; charset=utf-8", web::kSubjectHtml, {web::Role::kSubject}, ""};
  web::WebServer::Endpoint pages{"/subject/ws", {}, front, {web::Role::kSubject}, /*viewers=*/false};
  pages.handler_only_queues = true;  // the front's OnText only queues (online_front.hpp, Threads)
  so.endpoints.push_back(pages);
  so.pages["/overview"] = web::WebServer::Page{"text/html; charset=utf-8", kOverviewHtml, {web::Role::kExperimenter}, ""};
  so.endpoints.push_back(web::WebServer::Endpoint{"/overview/ws", {}, overview, {web::Role::kExperimenter}, /*viewers=*/false});
  so.max_clients = 4 * max_sessions + 16;  // the refused pages are told so over their socket
  so.max_frame_bytes = 16 << 10;           // a page's frames are small (pointer samples, answers): 16 KiB, not 1 MiB
  so.allowed_origins = PageOrigins(o, link_origins);
  return so;
}

void Serving(const Study& s, const ServeOptions& o, int port, int with_links, int max_sessions, const DomainRange& domains,
             const std::string& token) {
  const std::string scheme = o.tls_certificate.empty() ? "http://" : "https://";
  for (const std::string& host : web::UrlHosts(o.address))
    std::cout << "dyad study serve: " << s.name << " at " << scheme << host << ":" << port << "/subject?token=..." << std::endl;
  // The overview's link holds the experimenter's token: written to a private file, never printed
  // (the output may go to a journal or a CI log).
  std::string links;
  for (const std::string& host : web::UrlHosts(o.address))
    links += scheme + host + ":" + std::to_string(port) + "/overview?token=" + token + "\n";
  const std::string file = s.data + "/overview-link";
  if (Status st = WritePrivateFile(file, links, CreateMode::kReplace); st.ok())
    std::cout << "experimenter's overview: its link is in " << file << " (0600: it holds the token, kept in " << s.data
              << "/serve-tokens)" << std::endl;
  else
    std::cerr << "dyad study serve: the experimenter's overview: " << st.ToString() << " (its link: " << scheme << "HOST:" << port
              << "/overview?token= and the experimenter token in " << s.data << "/serve-tokens)" << std::endl;
  std::cout << "participants with links: " << with_links << " of " << s.participants.size()
            << (with_links < static_cast<int>(s.participants.size()) ? " (dyad study links " + s.file + " --base-url " + scheme +
                                                                           "HOST:" + std::to_string(port) + " makes the others')"
                                                                     : std::string())
            << "; max_sessions " << max_sessions << ", reconnect_s " << s.online.reconnect_s << "; trials on DDS domains "
            << domains.first << "-" << domains.last << " (one each)" << std::endl;
}

// Each running trial on a DDS domain of its own (trial_domains.hpp): --domains, online.domains,
// else from the graph's domain_id on.
StatusOr<DomainRange> ServeDomains(const Study& s, const ServeOptions& o, int max_sessions) {
  if (o.domains.empty()) return TrialDomainRange(s.online.domains, s.file + ": online.domains", s.graph_domain, max_sessions);
  const auto given = ParseDomainRange(o.domains);
  if (!given.ok()) return Status::InvalidArgument("--domains " + std::string(given.status().message()));
  return TrialDomainRange(*given, "--domains", s.graph_domain, max_sessions);
}

// A condition's own domain_id would be replaced by the trial's (the front's --set comes last):
// said once at start, not left to be found in the recordings.
void WarnConditionDomains(const Study& s, const DomainRange& domains) {
  for (const Condition& c : s.conditions)
    for (const std::string& set : c.sets)
      if (set.starts_with("domain_id="))
        std::cerr << "dyad study serve: " << s.file << ": condition '" << c.name << "' sets " << set
                  << ", which serve replaces: each running trial has a DDS domain of its own, from " << domains.first << "-"
                  << domains.last << "\n";
}

}  // namespace

std::vector<std::string> PageOrigins(const ServeOptions& o, const std::vector<std::string>& link_origins) {
  // --origin, and where the links are (DATA/links.csv: a name of this machine, a proxy's)
  std::vector<std::string> origins = o.origins;
  origins.insert(origins.end(), link_origins.begin(), link_origins.end());
  const std::string scheme = o.tls_certificate.empty() ? "http://" : "https://";
  for (const std::string& host : web::UrlHosts(o.address))
    origins.push_back(scheme + host + ":" + std::to_string(o.port));  // ":0": the port bound (--port 0)
  static constexpr std::pair<std::string_view, std::string_view> kDefaultPorts[] = {{"https://", ":443"}, {"http://", ":80"}};
  for (size_t i = 0, n = origins.size(); i < n; ++i) {
    const std::string origin = origins[i];  // a copy: the vector grows
    for (const auto& [scheme_of, port] : kDefaultPorts)
      if (origin.starts_with(scheme_of) && origin.ends_with(port))
        origins.push_back(origin.substr(0, origin.size() - port.size()));
  }
  return origins;
}

int Serve(const ServeOptions& o) {
  std::vector<Diagnostic> problems;
  const Study s = LoadStudy(o.file, o.plugins, &problems);
  for (const auto& p : problems) std::cerr << p.ToString() << "\n";
  if (!problems.empty()) {
    std::cerr << o.file << ": " << problems.size() << " problem" << (problems.size() == 1 ? "" : "s") << "\n";
    return 2;
  }
  if (std::string why = WhyNotServed(s, o); !why.empty()) {
    std::cerr << "dyad study serve: " << why << "\n";
    return 2;
  }
  const std::vector<std::string> link_origins = LinkOrigins(s);
  const auto tls = TlsLines(s, o, link_origins);
  if (!tls.ok()) {
    std::cerr << "dyad study serve: " << tls.status().message() << "\n";
    return 2;
  }
  const int max_sessions = o.max_sessions > 0 ? o.max_sessions : s.online.max_sessions;
  const auto domains = ServeDomains(s, o, max_sessions);
  if (!domains.ok()) {
    std::cerr << "dyad study serve: " << domains.status().message() << "\n";
    return 2;
  }
  WarnConditionDomains(s, *domains);
  std::vector<std::string> token_problems;
  FrontAdmission admission(s, &token_problems);
  for (const std::string& p : token_problems) std::cerr << "dyad study serve: " << p << " (that participant has no link)\n";
  const auto overview_token = ServeExperimenterToken(s);
  if (!overview_token.ok()) {
    std::cerr << "dyad study serve: " << overview_token.status().message() << "\n";
    return 2;
  }
  admission.SetExperimenterToken(*overview_token);
  struct sigaction sa {
  }, old_int{}, old_term{};
  sa.sa_handler = OnServeSignal;
  sa.sa_flags = SA_RESTART;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  // A trial's graph waits for the page (it comes back at once after the 1012), at most
  // reconnect_s: a page not back by then ends the trial anyway.
  OnlineFront front(s, FrontOptions{tools::ThisExecutable(), max_sessions, std::min(15.0, s.online.reconnect_s),
                                    std::chrono::milliseconds(2000), *domains});
  OverviewChannel overview(s, &front, max_sessions);
  auto server = web::WebServer::Start(ServerOptions(o, link_origins, &admission, &front, &overview, max_sessions));
  if (!server.ok()) {
    std::cerr << "dyad study serve: " << server.status().ToString() << "\n";
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    return 1;
  }
  front.SetServer(server->get());
  overview.SetServer(server->get());
  overview.Start();
  if (!o.port_file.empty()) std::ofstream(o.port_file) << (*server)->port() << "\n";
  Serving(s, o, (*server)->port(), admission.with_links(), max_sessions, *domains, *overview_token);
  std::cout << *tls << std::flush;
  while (!g_quit.load()) {
    front.Tick(OnlineFront::Clock::now());
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const int running = front.running();
  std::cout << "dyad study serve: stopping" << (running ? " (" + std::to_string(running) + " trials running are stopped)" : "")
            << std::endl;
  overview.Stop();
  overview.SetServer(nullptr);
  front.StopAll();
  front.SetServer(nullptr);
  server->reset();
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  std::cout << "dyad study serve: stopped" << std::endl;
  return 0;
}

void AddServeCommand(CLI::App* study, int& exit_code) {
  auto o = std::make_shared<ServeOptions>();
  auto* serve = study->add_subcommand(
      "serve",
      "Serve a study online: each participant opens their link (dyad study links) and does their trials from their browser");
  serve->add_option("study", o->file, "Study file (YAML)")->required()->check(CLI::ExistingFile);
  serve->add_option("--address", o->address, "Listen address (off loopback: with --tls-certificate)");
  serve->add_option("--port", o->port, "Port (0: any free one)")->check(CLI::Range(0, 65535));
  serve
      ->add_option("--tls-certificate", o->tls_certificate,
                   "PEM file (0600): private key, then certificate chain (HTTPS, WSS); "
                   "dyad security init KEYSTORE --graph GRAPH --web-host HOST makes KEYSTORE/web/tls.pem")
      ->check(CLI::ExistingFile);
  serve->add_option("--max-sessions", o->max_sessions, "Live sessions at once (default: the study file's online.max_sessions)")
      ->check(CLI::Range(1, 100000));
  serve->add_option("--domains", o->domains,
                    "FIRST-LAST: the DDS domains of the trials running at once, one each (default: the study file's "
                    "online.domains, else the graph's domain_id and the max_sessions - 1 after it)");
  serve->add_option("--port-file", o->port_file, "Write the bound port here");
  serve->add_option("--origin", o->origins, "Another origin participants' pages come from (scheme://host[:port], repeatable)");
  serve->add_option("--plugins", o->plugins, "Extra plugin file or folder (repeatable)");
  serve->callback([o, &exit_code] { exit_code = Serve(*o); });
}

}  // namespace dyad::study
