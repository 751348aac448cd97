// tools/study/study_analysis.hpp: `dyad study analyze`: every recording of a study's plan, one
// table across everyone (docs/study.md).
//
// Contract:
//   - AnalyzeStudy reads each planned trial's recording (Trial::file) with `dyad analyze`'s
//     BuildReport. A trial without its file, or with one that cannot be analysed, is listed as
//     missing with the reason; the analysis goes on with what exists.
//   - WriteStudyAnalysis writes into `dir` (created): trials.csv (one row per trial: participant,
//     condition, label, trial, repetition, file, then RunMetrics' measures), events.csv (one row
//     per event of every trial: participant, condition, trial, the event's steps, primitive,
//     self-report, congruence, the observer's accuracy on the human, whether the robot follows,
//     its switch latency), summary.csv (per condition and measure: each participant's mean over
//     their trials, then the mean over participants with a 95% percentile-bootstrap interval that
//     resamples participants, seeded from the study, condition and measure names),
//     reported_confusion.csv (the observer against the self-reports, summed over trials; only
//     when there are some) and report.md (the summary, the missing trials). Conditions are named
//     (the analysis is the unblinded step) with their labels beside them.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "dyad/status.hpp"
#include "experiment_analysis.hpp"
#include "study_file.hpp"

namespace dyad::study {

struct TrialResult {
  std::string participant;
  Trial trial;
  std::vector<std::pair<std::string, double>> metrics;  // analyze::RunMetrics
  std::vector<analyze::EventSummary> events;
};

struct StudyAnalysis {
  std::vector<TrialResult> trials;  // in the plan's order
  std::vector<std::string> missing;  // "P02 trial 3 (FILE): not recorded" and the like
  std::vector<std::vector<int64_t>> reported_confusion;  // empty: no self-report with labels
};

StudyAnalysis AnalyzeStudy(const Study& study, std::ostream& warnings);
Status WriteStudyAnalysis(const Study& study, const StudyAnalysis& analysis, const std::string& dir);

// The measures summarised per condition (names of RunMetrics).
const std::vector<std::string>& SummaryMeasures();

}  // namespace dyad::study
