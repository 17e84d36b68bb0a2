#include "harness/slurm_submit.h"

#include "core/atomic_file.h"
#include "harness/environment.h"
#include "harness/experiment_config.h"
#include "harness/runner.h"
#include "harness/slurm_script.h"
#include "harness/subprocess.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <stdexcept>

namespace mcf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// sbatch options that submit sets itself: given again among the extra arguments they would
/// break the submission (another array, no dependency, another thread count than the cells'
/// keys hold, no job id to read).
struct ReservedOption {
  const char* name;
  char short_name;  ///< 0: none
  const char* why;
};
constexpr ReservedOption kReserved[] = {
    {"array", 'a', "submit sets it to the shards that have cells to run (see --tasks)"},
    {"dependency", 'd', "submit makes the collect job depend on the array"},
    {"cpus-per-task", 'c',
     "use submit's own --cpus-per-task, which is also every cell's thread count"},
    {"parsable", 0, "submit reads the job ids with it"},
    {"ntasks", 'n', "use submit's own --ntasks (default: the largest mpi_ranks of the cells)"},
    {"nodes", 'N', "use submit's own --nodes"},
    {"wrap", 0, "submit writes the batch scripts itself"},
};

void check_sbatch_argument(const std::string& a) {
  // A word that is not an option would be taken by sbatch for the script to submit.
  if (a.size() < 2 || a[0] != '-')
    throw std::invalid_argument("extra sbatch argument \"" + a +
                                "\": give sbatch options one word each (--account=NAME, -ANAME)");
  auto refuse = [&](const ReservedOption& r) {
    throw std::invalid_argument("extra sbatch argument \"" + a + "\": --" + r.name + " is set by " +
                                "mcfbench submit (" + r.why + ")");
  };
  if (a.size() > 2 && a.compare(0, 2, "--") == 0) {
    // sbatch takes any unambiguous abbreviation of a long option (getopt_long).
    const std::string name =
        a.substr(2, a.find('=') == std::string::npos ? std::string::npos : a.find('=') - 2);
    for (const ReservedOption& r : kReserved)
      if (name.size() >= 3 && std::string(r.name).compare(0, name.size(), name) == 0) refuse(r);
  } else if (a.size() > 1 && a[0] == '-' && a[1] != '-') {
    for (const ReservedOption& r : kReserved)
      if (r.short_name != 0 && a[1] == r.short_name) refuse(r);
  }
}

std::string this_binary() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find this program's own path: " + ec.message());
  return self.string();
}

/// An absolute path without "." or ".." parts or a trailing separator.
std::string absolute_path(const std::string& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();
  return p.string();
}

/// The command line that submits the same again (named in the collect job's message).
std::string resubmit_command(const SubmitRequest& r, const BatchScriptInput& in) {
  std::vector<std::string> words = {in.mcfbench, "submit", in.config};
  if (r.quick) words.push_back("--quick");
  words.insert(words.end(), {"--out", in.out_dir, "--tasks", std::to_string(in.tasks),
                             "--cpus-per-task", std::to_string(r.cpus_per_task)});
  if (r.ntasks > 0) words.insert(words.end(), {"--ntasks", std::to_string(r.ntasks)});
  if (r.nodes > 0) words.insert(words.end(), {"--nodes", std::to_string(r.nodes)});
  if (!r.partition.empty()) words.insert(words.end(), {"--partition", r.partition});
  if (!r.time.empty()) words.insert(words.end(), {"--time", r.time});
  if (!r.mem.empty()) words.insert(words.end(), {"--mem", r.mem});
  if (!r.sbatch_args.empty()) {
    words.push_back("--");
    words.insert(words.end(), r.sbatch_args.begin(), r.sbatch_args.end());
  }
  return shell_join(words);
}

/// The record of the previous submission into the folder, if it left a readable one.
std::optional<json> read_record(const std::string& path) {
  if (!fs::exists(path)) return std::nullopt;
  std::ifstream in(path);
  json j = json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) {
    std::fprintf(stderr, "mcfbench submit: %s does not parse; ignoring it\n", path.c_str());
    return std::nullopt;
  }
  return j;
}

/// The job ids a record names.
std::vector<std::string> recorded_jobs(const json& record) {
  std::vector<std::string> ids;
  for (const char* key : {"array_job", "collect_job"})
    if (record.contains(key) && record[key].is_string() && !record[key].get<std::string>().empty())
      ids.push_back(record[key]);
  return ids;
}

std::string joined(const std::vector<std::string>& words, const std::string& separator) {
  std::string s;
  for (const std::string& w : words) {
    if (!s.empty()) s += separator;
    s += w;
  }
  return s;
}

/// Which of `ids` are still in Slurm's queue (pending, running, completing: what squeue lists
/// without --states). Returns nullopt when squeue failed (its message is on stderr).
std::optional<std::vector<std::string>> still_queued(const std::vector<std::string>& ids) {
  // Every job squeue lists, by the id of the job (an array task's "123_4" and a pending array's
  // "123_[5-9]" by their array's id). Not --jobs: squeue fails on a single id it no longer knows.
  const ProgramResult r = run_program({"squeue", "--noheader", "--format=%i"});
  if (!r.ok()) {
    std::fprintf(stderr, "mcfbench submit: squeue %s\n",
                 r.start_error.empty() ? ("exited with status " + std::to_string(r.status)).c_str()
                                       : ("could not be started: " + r.start_error).c_str());
    return std::nullopt;
  }
  std::set<std::string> listed;
  size_t start = 0;
  while (start < r.out.size()) {
    size_t end = r.out.find('\n', start);
    if (end == std::string::npos) end = r.out.size();
    std::string line = r.out.substr(start, end - start);
    line.erase(0, line.find_first_not_of(" \t"));
    listed.insert(line.substr(0, line.find_first_of("_ \t\r")));
    start = end + 1;
  }
  std::vector<std::string> queued;
  for (const std::string& id : ids)
    if (listed.count(id)) queued.push_back(id);
  return queued;
}

/// `sbatch --parsable OPTIONS... EXTRA... SCRIPT`: the job id, or nothing when sbatch failed or
/// printed no id (its own message is on stderr; `what` names the job in ours).
std::optional<std::string> sbatch(const std::vector<std::string>& options,
                                  const std::vector<std::string>& extra, const std::string& script,
                                  const std::string& what) {
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  argv.insert(argv.end(), options.begin(), options.end());
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back(script);
  const ProgramResult r = run_program(argv);
  if (!r.start_error.empty()) {
    std::fprintf(stderr, "mcfbench submit: cannot run sbatch (%s): is Slurm installed here?\n",
                 r.start_error.c_str());
    return std::nullopt;
  }
  if (!r.ok()) {
    std::fprintf(stderr, "mcfbench submit: sbatch refused the %s (exit status %d)\n", what.c_str(),
                 r.status);
    return std::nullopt;
  }
  // --parsable prints "ID" or "ID;CLUSTER".
  std::string id = r.out.substr(0, r.out.find_first_of(";\r\n"));
  id.erase(0, id.find_first_not_of(" \t"));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    std::fprintf(stderr,
                 "mcfbench submit: sbatch printed no job id for the %s but \"%s\"; check with "
                 "squeue whether it was submitted\n",
                 what.c_str(), r.out.c_str());
    return std::nullopt;
  }
  return id;
}

/// Cancels the jobs submitted before a later step failed, so that nothing stays half-submitted.
void cancel(const std::vector<std::string>& ids) {
  if (ids.empty()) return;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), ids.begin(), ids.end());
  const ProgramResult r = run_program(argv);
  if (r.ok())
    std::fprintf(stderr, "mcfbench submit: cancelled job(s) %s; nothing stays submitted\n",
                 joined(ids, ", ").c_str());
  else
    std::fprintf(stderr,
                 "mcfbench submit: could not cancel job(s) %s (scancel %s): cancel them by hand: "
                 "scancel %s\n",
                 joined(ids, ", ").c_str(),
                 r.start_error.empty() ? ("exit status " + std::to_string(r.status)).c_str()
                                       : r.start_error.c_str(),
                 joined(ids, " ").c_str());
}

}  // namespace

void check_submit_request(const SubmitRequest& r) {
  if (r.config.empty()) throw std::invalid_argument("submit: no experiment config given");
  if (r.out.empty())
    throw std::invalid_argument("submit: --out DIR is required (the results folder)");
  if (r.tasks < 0)
    throw std::invalid_argument("--tasks: expected a number of tasks >= 1, got " +
                                std::to_string(r.tasks));
  if (r.cpus_per_task < 1)
    throw std::invalid_argument("--cpus-per-task: expected a number >= 1, got " +
                                std::to_string(r.cpus_per_task));
  if (r.ntasks < 0)
    throw std::invalid_argument("--ntasks: expected a number >= 1, got " +
                                std::to_string(r.ntasks));
  if (r.nodes < 0)
    throw std::invalid_argument("--nodes: expected a number >= 1, got " + std::to_string(r.nodes));
  for (const std::string& a : r.sbatch_args) check_sbatch_argument(a);
}

namespace {

/// What the batch scripts say, as far as the request and the config tell it.
BatchScriptInput script_input(const SubmitRequest& r, const ExperimentConfig& e) {
  BatchScriptInput in;
  in.study = e.name;
  in.quick = r.quick;
  in.mcfbench = r.mcfbench.empty() ? this_binary() : absolute_path(r.mcfbench);
  in.config = absolute_path(r.config);
  in.out_dir = absolute_path(r.out);
  in.job = {r.partition, r.time, r.mem, r.cpus_per_task};
  in.with_reference = !e.metrics.reference.is_null();
  const fs::path report_script = fs::path(source_dir()) / "reports" / "make_report.py";
  if (fs::exists(report_script))
    in.report_script = report_script.string();
  else
    std::fprintf(stderr,
                 "mcfbench submit: %s is not there (was the source tree moved?): the collect job "
                 "will write no report\n",
                 report_script.c_str());
  return in;
}

/// The cells' thread count is part of their keys: a folder filled with another count would get
/// every cell a second time under other names.
void check_thread_count(const std::optional<json>& previous, const ExperimentConfig& e,
                        const SubmitRequest& r, const BatchScriptInput& in) {
  if (previous && previous->value("study", "") == e.name &&
      previous->value("quick", false) == r.quick &&
      previous->value("cpus_per_task", r.cpus_per_task) != r.cpus_per_task)
    throw std::invalid_argument(
        in.out_dir + " was submitted with --cpus-per-task " +
        std::to_string(previous->value("cpus_per_task", 0)) +
        ", which is every cell's thread count and so part of its key: submit again with the "
        "same, or into another folder");
}

/// The array: tasks, each job's MPI tasks and nodes, and the shards that still have cells to
/// run (as `mcfbench run` decides, by their result files); returns how many cells are to run.
int plan_array(const SubmitRequest& r, const ExperimentConfig& e,
               const std::vector<CellPlan>& plans, BatchScriptInput& in) {
  const int cells = int(plans.size());
  in.cells = cells;
  // Every array job gets the ranks of the cell that asks for the most (its shard may hold it).
  int ranks = 1;
  for (const CellPlan& p : plans) ranks = std::max(ranks, p.cell.flow.mpi_ranks);
  if (r.ntasks > 0 && r.ntasks < ranks)
    throw std::invalid_argument("--ntasks " + std::to_string(r.ntasks) + ": a cell of " + e.name +
                                " asks for mpi_ranks " + std::to_string(ranks) +
                                "; give at least that many, or leave --ntasks out");
  in.job.ntasks = r.ntasks > 0 ? r.ntasks : ranks;
  if (r.nodes > in.job.ntasks)
    throw std::invalid_argument("--nodes " + std::to_string(r.nodes) + ": more nodes than the " +
                                std::to_string(in.job.ntasks) + " tasks of each job");
  in.job.nodes = r.nodes;
  in.tasks = std::max(1, std::min(r.tasks > 0 ? r.tasks : kMaxArrayTasks, cells));
  std::set<int> shards;
  int to_run = 0;
  for (const CellPlan& p : plans)
    if (!cell_finished(p.file)) {
      ++to_run;
      shards.insert(p.cell.index % in.tasks);
    }
  in.array.assign(shards.begin(), shards.end());
  in.resubmit = resubmit_command(r, in);
  if (r.tasks > cells)
    std::printf("%s: %d tasks for %d cells: using %d\n", e.name.c_str(), r.tasks, cells, in.tasks);
  return to_run;
}

/// One submission at a time into a folder: a second array would run the cells the first one is
/// still running, both writing the same files. False (having said why) while the previous
/// submission's jobs are queued, or when squeue cannot tell.
bool previous_jobs_ended(const std::optional<json>& previous, const BatchScriptInput& in,
                         const SlurmPaths& paths) {
  if (!previous) return true;
  const std::vector<std::string> ids = recorded_jobs(*previous);
  if (ids.empty()) return true;
  const auto queued = still_queued(ids);
  if (!queued) {
    std::fprintf(stderr,
                 "mcfbench submit: cannot tell whether job(s) %s of the previous submission "
                 "into %s are still queued; nothing was submitted\n",
                 joined(ids, ", ").c_str(), in.out_dir.c_str());
    return false;
  }
  if (!queued->empty()) {
    std::fprintf(stderr,
                 "mcfbench submit: job(s) %s of the previous submission into %s are still "
                 "queued or running (squeue --jobs=%s); nothing was submitted. Submit again "
                 "once they have ended, or cancel them first (scancel %s). (%s names them.)\n",
                 joined(*queued, ", ").c_str(), in.out_dir.c_str(), joined(*queued, ",").c_str(),
                 joined(*queued, " ").c_str(), paths.record.c_str());
    return false;
  }
  return true;
}

/// The scripts, written before anything is submitted (a folder they cannot name is refused
/// here), and what they will run.
void write_scripts(const BatchScriptInput& in, const SlurmPaths& paths, int to_run,
                   const std::string& what) {
  const bool run_cells = !in.array.empty();
  const std::string run_text = run_cells ? run_array_script(in) : "";
  const std::string collect_text = collect_script(in);
  std::error_code ec;
  fs::create_directories(paths.logs, ec);  // Slurm does not create the folder of --output
  if (ec) throw std::runtime_error(paths.logs + ": cannot create the folder: " + ec.message());
  if (run_cells) write_file_atomic(paths.run_script, run_text);
  write_file_atomic(paths.collect_script, collect_text);
  if (run_cells)
    std::printf(
        "%s: %d cells, %d finished, %d to run in %zu of %d tasks (task i runs the cells "
        "whose index %% %d == i)\n",
        what.c_str(), in.cells, in.cells - to_run, to_run, in.array.size(), in.tasks, in.tasks);
  else
    std::printf("%s: all %d cells are finished; only the collect-and-report job is needed\n",
                what.c_str(), in.cells);
  std::printf("scripts: %s%s%s\n", run_cells ? paths.run_script.c_str() : "",
              run_cells ? " and " : "", paths.collect_script.c_str());
}

void print_by_hand(const SlurmPaths& paths, bool run_cells) {
  std::printf("dry run: nothing submitted. To submit them by hand:\n");
  if (run_cells) {
    std::printf("  array=$(sbatch --parsable %s)\n", shell_quote(paths.run_script).c_str());
    std::printf("  sbatch --dependency=afterany:${array%%%%;*} %s\n",
                shell_quote(paths.collect_script).c_str());
  } else {
    std::printf("  sbatch %s\n", shell_quote(paths.collect_script).c_str());
  }
}

struct SubmittedJobs {
  std::string array_job;  ///< empty where no cell was left to run
  std::string collect_job;
};

/// The array, then the collect job depending on it; nothing (having said why, and cancelled the
/// array) where sbatch refused either.
std::optional<SubmittedJobs> submit_jobs(const SubmitRequest& r, const SlurmPaths& paths,
                                         bool run_cells) {
  SubmittedJobs jobs;
  if (run_cells) {
    const auto id = sbatch({}, r.sbatch_args, paths.run_script, "job array");
    if (!id) {
      std::fprintf(stderr, "mcfbench submit: nothing was submitted\n");
      return std::nullopt;
    }
    jobs.array_job = *id;
  }
  std::vector<std::string> collect_options;
  if (run_cells) collect_options.push_back("--dependency=afterany:" + jobs.array_job);
  const auto collect_job =
      sbatch(collect_options, r.sbatch_args, paths.collect_script, "collect-and-report job");
  if (!collect_job) {
    if (run_cells)
      cancel({jobs.array_job});
    else
      std::fprintf(stderr, "mcfbench submit: nothing was submitted\n");
    return std::nullopt;
  }
  jobs.collect_job = *collect_job;
  return jobs;
}

/// submitted.json: what the next submission into the folder checks; the jobs are cancelled if
/// it cannot be written.
void record_submission(const SubmitRequest& r, const ExperimentConfig& e,
                       const BatchScriptInput& in, const SlurmPaths& paths, int to_run,
                       const SubmittedJobs& jobs) {
  const bool run_cells = !in.array.empty();
  const json record = {{"schema", 1},
                       {"study", e.name},
                       {"quick", r.quick},
                       {"config", in.config},
                       {"out", in.out_dir},
                       {"cells", in.cells},
                       {"cells_to_run", to_run},
                       {"tasks", in.tasks},
                       {"array", run_cells ? json(array_spec(in.array)) : json(nullptr)},
                       {"cpus_per_task", r.cpus_per_task},
                       {"array_job", jobs.array_job},
                       {"collect_job", jobs.collect_job},
                       {"command", in.resubmit}};
  try {
    write_file_atomic(paths.record, record.dump(1) + "\n");
  } catch (const std::exception&) {
    std::vector<std::string> ids = {jobs.collect_job};
    if (run_cells) ids.insert(ids.begin(), jobs.array_job);
    cancel(ids);
    throw;
  }
}

void print_submitted(const BatchScriptInput& in, const SlurmPaths& paths,
                     const SubmittedJobs& jobs) {
  const bool run_cells = !in.array.empty();
  const std::string logs = paths.logs;
  std::vector<std::string> ids;
  if (run_cells) {
    ids.push_back(jobs.array_job);
    std::printf("submitted job array %s (task(s) %s): logs %s/run-%s_<task>.out\n",
                jobs.array_job.c_str(), array_spec(in.array).c_str(), logs.c_str(),
                jobs.array_job.c_str());
  }
  ids.push_back(jobs.collect_job);
  std::printf("submitted job %s, collect and report%s: log %s/collect-%s.out\n",
              jobs.collect_job.c_str(), run_cells ? " once the array has ended" : "", logs.c_str(),
              jobs.collect_job.c_str());
  std::printf("follow them:     squeue --jobs=%s\n", joined(ids, ",").c_str());
  std::printf("once they ended: sacct --jobs=%s --format=JobID,JobName,State,Elapsed,ExitCode\n",
              joined(ids, ",").c_str());
  std::printf("results: %s (index.json)%s%s\n", in.out_dir.c_str(),
              in.report_script.empty() ? "" : ", report: ",
              in.report_script.empty() ? "" : (paths.report + "/index.md").c_str());
  std::printf(
      "Tasks lost to a time limit, a node failure or scancel: once these jobs have ended, submit "
      "again\n(the same command); it runs only the cells still missing or errored.\n");
}

}  // namespace

int submit_study(const SubmitRequest& r) {
  check_submit_request(r);
  const ExperimentConfig e = load_experiment_config(r.config, r.quick);
  BatchScriptInput in = script_input(r, e);
  const SlurmPaths paths = slurm_paths(in.out_dir);
  const std::optional<json> previous = read_record(paths.record);
  check_thread_count(previous, e, r, in);
  MeshCache meshes;
  const int to_run = plan_array(r, e, plan_cells(e, in.out_dir, meshes, r.cpus_per_task), in);
  if (!r.dry_run && !previous_jobs_ended(previous, in, paths)) return 1;
  write_scripts(in, paths, to_run, e.name + (r.quick ? " (quick variant)" : ""));
  const bool run_cells = !in.array.empty();
  if (r.dry_run) {
    print_by_hand(paths, run_cells);
    return 0;
  }
  const std::optional<SubmittedJobs> jobs = submit_jobs(r, paths, run_cells);
  if (!jobs) return 1;
  record_submission(r, e, in, paths, to_run, *jobs);
  print_submitted(in, paths, *jobs);
  return 0;
}

}  // namespace mcf
