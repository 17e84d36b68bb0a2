#pragma once
// `mcfbench collect DIR...`: merges result folders (e.g. the shards of a Slurm array) into one
// index file and checks them against the matrix `run` planned (DIR/plans/, written before its
// first cell) or, for folders without a plan, the matrix stored in the results: every cell
// present once. A folder holding neither results nor a plan is an error, not an empty success.

#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace mcf {

/// The results and plans of one study variant at one commit.
struct StudyResults {
  nlohmann::json study_config;
  std::string study, commit, source;
  bool quick = false;
  std::map<int, std::vector<std::string>> files_by_index;
  std::vector<int> without_distance;  ///< candidates; reference cells themselves are filtered out
  std::vector<int> errored;           ///< cells whose result is {"status": "error"}
  std::map<int, nlohmann::json> planned;  ///< index -> {repetition, assignment[, hash]} of plans
  std::vector<std::string> plans;         ///< the plan files read
};

/// Everything read from the result folders, grouped by study variant and commit.
struct ResultFolders {
  nlohmann::json files = nlohmann::json::array();  ///< one entry per cell result read
  std::map<std::string, StudyResults> studies;     ///< by "STUDY[-quick]@COMMIT"
  std::set<std::string> seen_hashes;
  nlohmann::json duplicates = nlohmann::json::array();  ///< a hash met in two folders
  nlohmann::json unreadable = nlohmann::json::array();  ///< files that do not parse
  nlohmann::json empty_dirs = nlohmann::json::array();  ///< folders with nothing to collect
};

/// collect as a whole: reads `dirs`, checks every study, writes the index to `index_file`
/// (default FIRST_DIR/index.json) and prints a summary. Returns 0 when every cell is there once,
/// 1 otherwise.
int collect_results(const std::vector<std::string>& dirs, const std::string& index_file);

}  // namespace mcf
