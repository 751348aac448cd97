// tools/study/study_analysis.hpp: `dyad study analyze`: every recording of a study's plan, one
// table across everyone (docs/study.md).
//
// Contract:
//   - AnalyzeStudy reads each planned trial's recording with `dyad analyze`'s BuildReport: the
//     last complete attempt the participant's session log names (study_session.hpp), or
//     Trial::file when the log knows nothing of the trial. Listed as missing with the reason, and
//     left out, while the analysis goes on with what exists: a trial not recorded; one whose
//     attempts all ended incomplete (stopped early, failed, or the session ended mid-trial); a
//     file that cannot be analysed; a recording whose "dyad.run" metadata does not say it is this
//     trial of this participant of this study (another study's file, a rehearsal's among the
//     participants' or the reverse, or a file without that metadata).
//   - Every other .mcap file in a participant's folder is listed as not part of the plan.
//   - A participant who withdrew consent, or whom the researcher excluded, is left out whole
//     (no trial, no missing trial) and listed with the reason. The experimenter's session notes
//     go into the report, except a withdrawn participant's.
//   - WriteStudyAnalysis writes into `dir` (created): trials.csv (one row per trial: participant,
//     condition, label, trial, repetition, attempt, file, then RunMetrics' measures), events.csv (one row
//     per event of every trial: participant, condition, trial, the event's steps, primitive,
//     self-report, congruence, the observer's accuracy on the human, whether the robot follows,
//     its switch latency), summary.csv (per condition and measure: each participant's mean over
//     their trials, then the mean over participants with a 95% percentile-bootstrap interval that
//     resamples participants, seeded from the study, condition and measure names),
//     reported_confusion.csv (the observer against the self-reports, summed over trials; only
//     when there are some), reports_vs_plan.csv (synthetic participants: the primitive each traced
//     against the one it reported, per event; only when there are some) and report.md (the summary, the missing trials). Conditions are named
//     (the analysis is the unblinded step) with their labels beside them.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "dyad/status.hpp"
#include "experiment_analysis.hpp"
#include "study_file.hpp"
#include "study_session.hpp"

namespace dyad::study {

struct TrialResult {
  std::string participant;
  Trial trial;
  int attempt = 1;       // the attempt analysed (its file: Trial::file for attempt 1)
  bool planned = false;  // a synthetic human's trial: each event's primitive is the one it traced
  std::string repeated;  // the earlier attempts' fate and reasons, for the report
  std::vector<std::pair<std::string, double>> metrics;  // analyze::RunMetrics
  std::vector<analyze::EventSummary> events;
};

struct StudyAnalysis {
  std::vector<TrialResult> trials;  // in the plan's order
  std::vector<std::string> missing;  // "P02 trial 3 (FILE): not recorded" and the like
  std::vector<std::string> unplanned;  // .mcap files in a participant's folder that are no attempt of the plan
  std::vector<std::string> left_out;   // "P03: withdrew consent on ...", "P04: excluded: REASON"
  std::vector<std::pair<std::string, Note>> notes;  // (participant, note), in the plan's order of participants
  // The files name the conditions (the unblinded step); false: "condition A" only (a blind
  // study's rehearsal, seen by the experimenter before the study).
  bool unblinded = true;
  std::vector<std::vector<int64_t>> reported_confusion;  // empty: no self-report with labels
  // Planned trials only: (traced primitive, reported choice) -> events; how wrong the reports are.
  std::map<std::pair<int, int>, int64_t> reports_vs_plan;
};

// `rehearsal`: the recordings `dyad study rehearse` made (their metadata says so), in study.data.
StudyAnalysis AnalyzeStudy(const Study& study, std::ostream& warnings, bool rehearsal = false);

// Empty when `file`'s "dyad.run" metadata names this study, participant, trial, condition (its
// label when blind) and rehearsal flag; else why not.
std::string NotThisTrial(const std::string& file, const Study& study, const std::string& participant, const Trial& trial,
                         bool rehearsal);
Status WriteStudyAnalysis(const Study& study, const StudyAnalysis& analysis, const std::string& dir);

// The measures summarised per condition (names of RunMetrics).
const std::vector<std::string>& SummaryMeasures();

}  // namespace dyad::study
