// tools/study/study_file.hpp: a study file, read and checked, and the plan it fixes: who does
// which condition when (docs/study.md).
//
//   study: gain                          # its name (letters, digits, _ and -)
//   graph: ../configs/interactive.yaml   # the base graph, relative to this file
//   data: gain-data                      # where recordings go (default <name>-data beside this file)
//   participants: [P01, P02, P03, P04]   # pseudonymous IDs only: 1-4 letters then 1-4 digits
//   conditions:                          # each a set of overrides, as `dyad run --set` takes them
//     assist: {mixer.gain: 0.3}
//     follow: {mixer.gain: 0.9}
//   trials: 2                            # per condition and participant (default 1)
//   duration: 120                        # seconds per trial (default 0: until the experimenter stops it)
//   blind: true                          # the experimenter sees "condition A", not its name (default false)
//   consent_required: true               # no trial records before consent is marked (default true)
//   self_reports: after_event            # when the subject's page asks about the holds: SelfReports (self_reports.hpp)
//   recorder: recorder                   # the graph's recorder component (default recorder)
//   rehearsal:                           # `dyad study rehearse`: synthetic participants instead of people
//     graph: ../demo.yaml                # the graph they are run on, stepped (default: the study's graph)
//     set: {human.self_report_error: 0.2}   # its own overrides, under each condition's
//   online:                              # `dyad study serve` (docs/study.md, "A study online")
//     reconnect_s: 60                    # a page gone mid-trial may come back this long (default 60, > 0)
//     max_sessions: 16                   # live sessions at once (default 16, >= 1; --max-sessions overrides)
//     domains: [40, 55]                  # each running trial's graph on a DDS domain of its own from these
//                                        # (default: the graph's domain_id and the max_sessions - 1 after it;
//                                        # --domains overrides; trial_domains.hpp)
//     completion_code: C1A2B3            # one code for everyone (letters, digits, _ -; default: one each)
//     consent: consent.txt               # the consent page's text, relative to this file (required
//                                        # to serve a study with consent_required)
//
// Contract of LoadStudy:
//   - Every problem of the file at once, each "file:line:col: key: message": unknown keys, wrong
//     types, a participant ID that is not pseudonymous or is used twice, also in another case
//     (AB12, ab12: one folder on a case-insensitive file system; naming the first), no
//     conditions, a condition that overrides nothing, an override the graph refuses (checked as
//     `dyad validate --set` would, at the line of that value, and each condition as a whole), an
//     `online:` map whose trials' domains (online.domains, else from the graph's domain_id on)
//     cannot hold online.max_sessions (at the key that limits it).
//   - The rehearsal graph, with its overrides, is checked against every condition like the
//     study's graph (a condition must mean the same keys in both); a condition already refused
//     above is not checked again (each problem is said once).
//   - The plan is a function of the file alone, fixed before the first participant comes:
//     participant i (file order) does the conditions in row i of a balanced Latin square
//     (latin_square.hpp), each as `trials` consecutive trials; blind labels A, B, ... are given
//     to the conditions in an order drawn from the study's name (the same every time).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dyad/diagnostic.hpp"
#include "self_reports.hpp"
#include "study_task.hpp"
#include "trial_domains.hpp"

namespace dyad::study {

struct Condition {
  std::string name, label;  // label: "A", "B", ... (what a blind experimenter sees)
  std::vector<std::string> sets;  // "KEY=VALUE", as `dyad run --set` takes them
  StudyTask task;                 // what the subject's page shows (the file's `task`, then its own)
};

struct Trial {
  int number = 1;      // 1.. within the participant's session
  int condition = 0;   // index in Study::conditions
  int repetition = 1;  // 1..trials within its condition
  std::string file;    // the recording: DATA/PARTICIPANT/NN-CONDITION.mcap (the label when blind)
};

// The `online:` map: what `dyad study serve` needs beyond the lab's keys.
struct Online {
  double reconnect_s = 60;      // > 0
  int max_sessions = 16;        // >= 1
  std::optional<DomainRange> domains;  // the trials' domains (none given: from the graph's domain_id)
  std::string completion_code;  // empty: a random code per participant (OnlineSession makes it)
  std::string consent;          // the consent text's file, absolute; empty: none given
  std::string consent_text;     // its text (read by LoadStudy: not empty)
};

struct Study {
  std::string name, file, graph, data;  // graph and data absolute
  int graph_domain = 0;                 // the graph's domain_id
  std::vector<std::string> participants;
  std::vector<Condition> conditions;
  int trials = 1;
  double duration_s = 0;
  bool blind = false, consent_required = true;
  SelfReports self_reports = SelfReports::kAfterEvent;
  std::string recorder = "recorder";  // the component whose `file` and `metadata` each trial sets
  std::vector<std::string> page_sets;  // "WEB.self_reports=MODE" for each `web` component of the graph
  std::vector<std::string> token_file_webs;  // web components without a token_file: one per participant is given
  // The web component whose subject's page a person steers from (the graph's one `web`, with a
  // `web_human`, given a token file, without TLS): `dyad study run --page` serves that page
  // between trials on its address and port (subject_lobby.hpp). Empty: none.
  std::string subject_web, subject_address = "127.0.0.1";
  StudyTask task;                     // the file's `task` (each condition starts from it)
  int subject_port = 8765;            // its params.port (the web component's default)
  std::string rehearsal_graph;        // absolute; the study's graph unless the file names another
  std::vector<std::string> rehearsal_sets;
  Online online;
  int square_rows = 1;  // rows of the Latin square: participants in multiples of it are balanced

  // The trials of `participant` (one of `participants`) in their order.
  std::vector<Trial> TrialsOf(const std::string& participant) const;
  // The conditions' indices in the order every listing shows them (plan, report, summary.csv,
  // plots): by label when blind (the file's order would tell which label is which condition to
  // whoever knows the file), else the file's order.
  std::vector<size_t> ListingOrder() const;
  // What the experimenter is shown of a condition: its label when blind, else its name.
  std::string Shown(const Condition& c) const { return blind ? "condition " + c.label : c.name; }
};

Study LoadStudy(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems);

}  // namespace dyad::study
