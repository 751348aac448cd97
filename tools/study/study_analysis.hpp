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
//   - An attempt the session log says ended "incomplete" (nobody took part: NoSubject) is
//     analysed when the trial has no complete attempt, and marked incomplete as below.
//   - A trial whose recording is analysed but incomplete (analyze::IncompleteReason: the file is
//     cut short or damaged, or spans less than 95% of the study's `duration`; or EmptyTrialReason:
//     nobody took part, no human input or not one engaged step) is kept in
//     trials.csv and events.csv, marked (complete false, its reason), and left out of everything
//     summed over trials (summary.csv, the confusion, reports_vs_plan.csv, the plots) unless
//     include_incomplete; report.md lists it with its reason.
//   - Every other .mcap file in a participant's folder is listed as not part of the plan.
//   - A participant who withdrew consent, or whom the researcher excluded, is left out whole
//     (no trial, no missing trial) and listed with the reason. The experimenter's session notes
//     go into the report, except a withdrawn participant's.
//   - WriteStudyAnalysis writes into `dir` (created): trials.csv (one row per trial: participant,
//     condition, label, trial, repetition, attempt, file, complete, reason, then TrialMeasures()),
//     events.csv (one row per event of every trial: participant, condition, trial, the event's
//     steps, primitive, self-report, congruence, the observer's accuracy on the human, whether
//     the robot follows, its switch latency, whether its trial is complete), summary.csv (per
//     condition and measure: each participant's mean over their trials (summed in the plan's
//     order), then the mean over participants (summed in ID order) with a 95% percentile-bootstrap
//     interval that resamples participants, seeded from the study, condition and measure names),
//     reported_confusion.csv (reported,observer,events,steps: the primitive the participant said
//     they drew, by its name (names.txt of the graph's data set; "primitive K" without one) or
//     "something else", against the observer's most likely class over the event's labelled steps
//     (the class most of them name; "no label": none), counted in events, with the labelled steps
//     of those reports on which the observer named that class beside; summed over the counted
//     trials; only when there are self-reports), reports_vs_plan.csv (synthetic participants: the primitive each traced
//     against the one it reported, by name as above, in events; only when there are some) and report.md (the
//     summary; per condition the observer's confusion against the self-reports and its accuracy
//     with its interval; the incomplete and the missing trials). Conditions are named (the
//     analysis is the unblinded step) with their labels beside them, listed in
//     Study::ListingOrder (by label when blind). Numbers in the CSV files are exact
//     (tools::CsvNumber): a summary recomputed from trials.csv as above is the same double.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "dyad/status.hpp"
#include "experiment_analysis.hpp"
#include "report_writer.hpp"
#include "study_file.hpp"
#include "study_session.hpp"

namespace dyad::study {

// A cell of the self-reports against the observer: events, and labelled steps.
struct SaidCell {
  int64_t events = 0, steps = 0;
};
// (what was said: a primitive, -1 "something else"; the observer's class, -1 "no label") -> cell.
using SaidVsObserver = std::map<std::pair<int, int>, SaidCell>;

struct TrialResult {
  std::string participant;
  Trial trial;
  int attempt = 1;       // the attempt analysed (its file: Trial::file for attempt 1)
  bool planned = false;  // a synthetic human's trial: each event's primitive is the one it traced
  std::string repeated;  // the earlier attempts' fate and reasons, for the report
  std::vector<std::pair<std::string, double>> metrics;  // analyze::RunMetrics
  std::vector<analyze::EventSummary> events;
  // Why its recording is incomplete (analyze::IncompleteReason against the study's duration); "": whole.
  std::string incomplete;
  std::vector<std::vector<int64_t>> reported_confusion;  // its own, in steps: [reported][the observer's class]
  SaidVsObserver said_vs_observer;  // its own, in events (reported_confusion.csv)
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
  bool include_incomplete = false;  // --include-incomplete: incomplete trials are summed too
  // Whether a trial counts in what is summed over trials.
  bool Counted(const TrialResult& r) const { return r.incomplete.empty() || include_incomplete; }
  std::vector<std::vector<int64_t>> reported_confusion;  // of the counted trials; empty: no self-report with labels
  SaidVsObserver said_vs_observer;                       // of the counted trials; empty: no self-report
  std::vector<std::string> primitive_names;              // the graph's data set's (names.txt); empty: unknown
  // Planned and counted trials only: (traced primitive, reported choice) -> events; how wrong the reports are.
  std::map<std::pair<int, int>, int64_t> reports_vs_plan;
};

// `rehearsal`: the recordings `dyad study rehearse` made (their metadata says so), in study.data.
// `include_incomplete`: incomplete trials count in the sums (StudyAnalysis::Counted).
StudyAnalysis AnalyzeStudy(const Study& study, std::ostream& warnings, bool rehearsal = false, bool include_incomplete = false);

// Why a trial's recording holds no participation, "" when someone took part: no human input
// recorded (human/input), or not one engaged step (kNoEngagedStep: no subject's page connected,
// or nobody held).
// Such a trial is incomplete: empty trials are not data.
std::string EmptyTrialReason(const analyze::Report& report);

// The self-reports of `report`'s events against the observer (SaidVsObserver).
SaidVsObserver SaidAgainstObserver(const analyze::Report& report);

// Empty when `file`'s "dyad.run" metadata names this study, participant, trial, condition (its
// label when blind) and rehearsal flag; else why not.
std::string NotThisTrial(const std::string& file, const Study& study, const std::string& participant, const Trial& trial,
                         bool rehearsal);
Status WriteStudyAnalysis(const Study& study, const StudyAnalysis& analysis, const std::string& dir);

// A trial's measures, trials.csv's columns: RunMetrics', then reported_accuracy (the share of
// the labelled steps of events with a self-report where the observer's most likely class is the
// reported primitive; NaN: none).
std::vector<std::string> TrialMeasures();
// The measures summarised per condition (of TrialMeasures).
const std::vector<std::string>& SummaryMeasures();

}  // namespace dyad::study
