#pragma once
// `mcfbench compare OLD NEW`: cell-by-cell performance and accuracy comparison of two result
// sets (e.g. two commits), for regression tracking. Cells are matched by their config key
// (config + input mesh, without code version or repetition). A cell's samples are its
// repetitions, one number each (the median step after the first), so the U test measures how
// much whole runs vary, not how much steps of one run do; two sets are compared only when they
// come from the same kind of machine, thread counts and build.

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace mcf {

struct CellSamples {
  std::string label;  ///< "basis=hat solver.name=cholmod" (the assignment)
  /// One sample per repetition that has one: for `seconds.total` the cell's
  /// `timing.step_median_seconds` where recorded, else the median of the metric over steps 2..N
  /// (step 1 alone when it is the only step).
  std::vector<double> values;
  /// What the timings depend on besides the code (`machine_identity`), from the first
  /// repetition; `mixed_identity` when a later repetition's differs.
  nlohmann::json identity = nlohmann::json::object();
  bool mixed_identity = false;
  /// Accuracy per repetition by measure: "reference_distance" (the final distance to the
  /// reference flow, RMS) and "radial_error" (the last step's radial RMS), where recorded.
  std::map<std::string, std::vector<double>> errors;
  int repetitions = 0;
  int failed = 0;       ///< repetitions whose status is not "ok" (singular or error)
  int errored = 0;      ///< of those, the ones with status "error" (the flow threw)
  std::string failure;  ///< the first such repetition's status and stop reason
  int min_steps = -1;   ///< fewest steps any repetition recorded
};

struct ResultSet {
  std::string dir, commit, study;
  std::map<std::string, CellSamples> cells;  ///< by config key
  /// Sums over the cells that record both (`run_seconds`, `steal_seconds`): the share of their
  /// run time that the hypervisor gave to other guests, to tell a noisy machine from slower code.
  double run_seconds = 0, steal_seconds = 0;
  /// Repetitions that record `contention`, and of those the ones that shared the machine with
  /// other work (`contention.contended`): their timings measure the machine as well as the code.
  int contention_recorded = 0, contended = 0;
};

struct CompareOptions {
  double threshold = 0.1, alpha = 0.05;
  std::string metric = "seconds.total";
  bool show_all = false;  ///< table lists unchanged cells too
  /// Compare cells whose machine, threads or build differ (listed in the report) instead of
  /// refusing to.
  bool allow_cross_machine = false;
};

/// The smallest two-sided p-value the U test can give with n1 and n2 samples (all of one sample
/// below all of the other): when it is not below alpha, no difference can be significant.
double smallest_mann_whitney_p(int n1, int n2);

struct CellComparison {
  std::string key, label;
  double old_median = 0, new_median = 0, ratio = 1, p_value = 1;
  int n_old = 0, n_new = 0;
  bool has_error = false;
  double old_error = 0, new_error = 0, error_ratio = 1;
  bool slower = false, faster = false, less_accurate = false;
  /// Too few repetitions on one side for the U test to ever reach alpha: the ratio is shown
  /// but cannot make the cell slower or faster.
  bool untestable = false;
  /// NEW failed (status not "ok") where OLD never did, or errored where OLD at worst stopped as
  /// singular, or stopped earlier than OLD's fewest steps: a regression whatever the timings say
  /// (a cell that errors has no timings at all).
  bool failed = false, stopped_earlier = false;
  /// OLD measured its accuracy in a way NEW did not (`missing_accuracy` names it): NEW's
  /// accuracy cannot be vouched for (reference distances not filled in, frames lost), a
  /// regression as a missing cell is.
  bool accuracy_missing = false;
  std::string missing_accuracy;
  std::string failure;
  int old_steps = 0, new_steps = 0;
};

struct CompareReport {
  std::vector<CellComparison> cells;
  std::vector<std::string> only_old, only_new;  ///< labels of unmatched cells
  /// Slower, less accurate, failed, stopped earlier, or a cell of OLD missing from NEW.
  bool regression = false;
  /// With allow_cross_machine: the matched cells whose identities differ ("label: difference").
  std::vector<std::string> cross_machine;
};

struct CompareRequest {
  std::string old_dir, new_dir;  ///< DIR[@COMMIT] each
  CompareOptions options;
  bool store_history = false;  ///< store NEW in the history `history` (store_in_history)
  std::string history;         ///< empty: data/history
};

/// compare as a whole: loads both sets, prints the Markdown comparison on stdout, stores NEW in
/// the history when asked (throws if it cannot). Returns 1 on a regression, else 0.
int compare_and_record(const CompareRequest& request);

/// Two-sided p-value of the Mann–Whitney U test (normal approximation, tie-corrected, with
/// continuity correction). 1 when either sample is empty or all values tie.
double mann_whitney_p(const std::vector<double>& a, const std::vector<double>& b);
double median(std::vector<double> v);

}  // namespace mcf
