#include "harness/slurm_script.h"

#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace mcf {
namespace {

namespace fs = std::filesystem;

/// A value of an #SBATCH line: bare when it is one plain word, else in double quotes, which
/// sbatch strips. Double quotes, backslashes and line breaks have no spelling there.
std::string sbatch_value(const std::string& value, const std::string& what) {
  for (const char ch : value)
    if (ch == '"' || ch == '\\' || ch == '\n' || ch == '\r')
      throw std::invalid_argument(what + " \"" + value +
                                  "\" holds a double quote, a backslash or a line break, which a "
                                  "batch script's #SBATCH line cannot carry");
  bool plain = !value.empty();
  for (const char ch : value)
    if (std::isspace(static_cast<unsigned char>(ch)) || ch == '#' || ch == '\'') plain = false;
  return plain ? value : "\"" + value + "\"";
}

/// A file name pattern of --output: `%` is Slurm's escape there, a literal one is `%%`.
std::string literal_in_pattern(const std::string& path) {
  std::string s;
  for (const char ch : path) {
    s += ch;
    if (ch == '%') s += '%';
  }
  return s;
}

/// The study's name as part of a job name: letters, digits, '.', '_' and '-' only.
std::string job_name(const std::string& study, const std::string& suffix) {
  std::string name = "mcfbench-" + study + suffix;
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_' && ch != '-')
      ch = '_';
  return name;
}

std::string variant(const BatchScriptInput& in) {
  return in.study + (in.quick ? " (quick variant)" : "");
}

/// The #SBATCH lines every job of a submission shares, after its own name and output.
std::string common_lines(const BatchScriptInput& in) {
  std::string s = "#SBATCH --cpus-per-task=" + std::to_string(in.job.cpus_per_task) + "\n";
  if (!in.job.partition.empty())
    s += "#SBATCH --partition=" + sbatch_value(in.job.partition, "--partition") + "\n";
  if (!in.job.time.empty()) s += "#SBATCH --time=" + sbatch_value(in.job.time, "--time") + "\n";
  if (!in.job.mem.empty()) s += "#SBATCH --mem=" + sbatch_value(in.job.mem, "--mem") + "\n";
  return s;
}

std::string output_line(const BatchScriptInput& in, const std::string& file_pattern) {
  const std::string logs = slurm_paths(in.out_dir).logs;
  return "#SBATCH --output=" +
         sbatch_value(literal_in_pattern(logs) + "/" + file_pattern, "the results folder") + "\n";
}

/// `mcfbench run CONFIG [--quick] --out OUT`, quoted.
std::string run_words(const BatchScriptInput& in) {
  std::vector<std::string> words = {in.mcfbench, "run", in.config};
  if (in.quick) words.push_back("--quick");
  words.push_back("--out");
  words.push_back(in.out_dir);
  return shell_join(words);
}

/// The thread count of every cell: the job's CPUs, and when the script runs outside Slurm the
/// number it was submitted with (the cells' keys hold it, so it must not change).
std::string threads_word(const BatchScriptInput& in) {
  return "\"${SLURM_CPUS_PER_TASK:-" + std::to_string(in.job.cpus_per_task) + "}\"";
}

}  // namespace

SlurmPaths slurm_paths(const std::string& out_dir) {
  const fs::path out(out_dir);
  const fs::path folder = out / "slurm";
  return {folder.string(),
          (folder / "run.sbatch").string(),
          (folder / "collect.sbatch").string(),
          (folder / "logs").string(),
          (folder / "submitted.json").string(),
          (out / "report").string()};
}

std::string shell_quote(const std::string& word) {
  static const std::string plain =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:@%+,";
  if (!word.empty() && word.find_first_not_of(plain) == std::string::npos) return word;
  std::string s = "'";
  for (const char ch : word) s += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return s + "'";
}

std::string shell_join(const std::vector<std::string>& words) {
  std::string s;
  for (const std::string& w : words) {
    if (!s.empty()) s += ' ';
    s += shell_quote(w);
  }
  return s;
}

std::string array_spec(const std::vector<int>& tasks) {
  std::string s;
  for (size_t i = 0; i < tasks.size();) {
    size_t j = i;
    while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
    if (!s.empty()) s += ",";
    s += std::to_string(tasks[i]);
    if (j > i) {
      s += '-';
      s += std::to_string(tasks[j]);
    }
    i = j + 1;
  }
  return s;
}

std::string run_array_script(const BatchScriptInput& in) {
  const std::string n = std::to_string(in.tasks);
  const bool all = int(in.array.size()) == in.tasks;
  std::string s = "#!/bin/bash\n";
  s += "# Written by `mcfbench submit`, again at every submission into this folder.\n";
  s += "# A job array over study " + variant(in) + ", " + in.config + ":\n";
  s += "# its " + std::to_string(in.cells) + " cells split into " + n + " shards by cell index % " +
       n + ". Array task i runs the cells of shard i\n";
  s += "# that have no finished result, each with as many threads as the task has CPUs. A task\n";
  s += "# that ends early (a time limit, a node failure, scancel) loses only the cell it was\n";
  s += "# running: submitting again runs the cells still missing or errored.\n";
  s += all ? "# This submission runs every task.\n"
           : "# This submission runs task(s) " + array_spec(in.array) +
                 ": the other shards have no cell left to run.\n";
  s += "#SBATCH --job-name=" + job_name(in.study, "") + "\n";
  s += "#SBATCH --array=" + array_spec(in.array) + "\n";
  s += output_line(in, "run-%A_%a.out");
  s += common_lines(in);
  if (in.job.ntasks > 1)  // the ranks of the cells that run across MPI ranks (mpi_ranks)
    s += "#SBATCH --ntasks=" + std::to_string(in.job.ntasks) + "\n";
  if (in.job.nodes > 0) s += "#SBATCH --nodes=" + std::to_string(in.job.nodes) + "\n";
  s += "set -eu\n";
  s += "exec " + run_words(in) + " \\\n";
  s += "  --shard \"${SLURM_ARRAY_TASK_ID:?submit this script with sbatch}/" + n + "\" \\\n";
  s += "  --threads " + threads_word(in) + "\n";
  return s;
}

std::string collect_script(const BatchScriptInput& in) {
  std::string s = "#!/bin/bash\n";
  s += "# Written by `mcfbench submit`, again at every submission into this folder.\n";
  s += "# Runs once the job array over study " + variant(in) +
       " has ended, however its tasks ended\n";
  s += "# (--dependency=afterany):\n";
  if (in.with_reference)
    s += "# - adds the distances to the reference cells that the tasks could not compute (the\n"
         "#   reference cell was another shard's);\n";
  s += "# - checks that every cell of the matrix is there once (`mcfbench collect`, which writes\n";
  s += "#   " + in.out_dir + "/index.json)";
  s += in.report_script.empty() ? ".\n" : ";\n";
  if (!in.report_script.empty())
    s += "# - writes the report into " + slurm_paths(in.out_dir).report +
         ", marked incomplete where cells are missing.\n";
  s += "# Exits 1 when cells are missing or errored, naming the command that runs them.\n";
  s += "#SBATCH --job-name=" + job_name(in.study, "-collect") + "\n";
  s += output_line(in, "collect-%j.out");
  s += common_lines(in);
  s += "set -u\n";
  s += "status=0\n";
  s += "complete=yes\n";
  if (in.with_reference) {
    s += "# No cell runs here: only distances between cells that are there.\n";
    s += run_words(in) + " \\\n  --threads " + threads_word(in) + " --distances-only || status=1\n";
  }
  s += shell_join({in.mcfbench, "collect", in.out_dir}) + " || complete=no\n";
  if (!in.report_script.empty())
    s += shell_join({in.python, in.report_script, in.out_dir, slurm_paths(in.out_dir).report}) +
         " || status=1\n";
  s += "if [ \"$complete\" = no ]; then\n";
  s += "  echo 'Cells are missing or errored (above). To run them, submit again:' >&2\n";
  s += "  echo " + shell_quote("  " + in.resubmit) + " >&2\n";
  s += "  status=1\n";
  s += "fi\n";
  s += "exit $status\n";
  return s;
}

}  // namespace mcf
