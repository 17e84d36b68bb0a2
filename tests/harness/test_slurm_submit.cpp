// `mcfbench submit` without a cluster: the batch scripts (quoting, #SBATCH lines, what runs),
// checked by bash and run by hand; the arguments it refuses before writing anything; and, with
// fake sbatch, squeue and scancel first on PATH that log their arguments, what it submits, that a
// refusing sbatch's own message and a non-zero exit reach the user with nothing left submitted,
// and that a second submission runs only the shards with cells left (tests/tools/
// test_slurm_live.sh does the same against a real Slurm).

#include "harness/slurm_script.h"
#include "harness/slurm_submit.h"

#include "harness_test_util.h"

#include <algorithm>
#include <stdexcept>

namespace mcf {
namespace {

using namespace mcf::test;
using nlohmann::json;

const char* tiny_reference_config = R"({
  "name": "tiny",
  "defaults": {"mesh": "icosphere:level=1", "steps": 2},
  "axes": {"dt": [0.001, 0.002, 0.003]},
  "metrics": {"frames": [2], "reference": {"dt": 0.001}, "distance_samples": 100}
})";

/// `bash -n`: the script parses.
bool bash_parses(const fs::path& script) {
  const std::string cmd = "bash -n " + shell_quote(script.string()) + " 2>/dev/null";
  return std::system(cmd.c_str()) == 0;
}

bool has_matplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib, numpy' >/dev/null 2>&1") == 0;
}

/// A folder of fake Slurm commands: each appends its name and arguments to calls.log; sbatch
/// prints job ids 4241, 4242, ... or, for the call numbered in the file `fail_at`, prints the
/// file `message` on stderr and exits 1; squeue prints the file `queue`; scancel succeeds.
struct FakeSlurm {
  fs::path bin;
  explicit FakeSlurm(const fs::path& dir) : bin(dir / "fake bin") {
    fs::create_directories(bin);
    write_script("sbatch", R"sh(n=$(( $(cat "$here/count" 2>/dev/null || echo 0) + 1 ))
echo $n >"$here/count"
if [ "$(cat "$here/fail_at" 2>/dev/null)" = $n ]; then cat "$here/message" >&2; exit 1; fi
echo $((4240 + n)))sh");
    write_script("squeue", R"(cat "$here/queue" 2>/dev/null; true)");
    write_script("scancel", "true");
  }
  void write_script(const std::string& name, const std::string& body) {
    write_text(bin / name, "#!/bin/bash\nhere=$(dirname \"$0\")\nprintf '%s' " + name +
                               " >>\"$here/calls.log\"\nfor a in \"$@\"; do printf ' [%s]' "
                               "\"$a\" >>\"$here/calls.log\"; done\necho >>\"$here/calls.log\"\n" +
                               body + "\n");
    fs::permissions(bin / name, fs::perms::owner_all, fs::perm_options::add);
  }
  std::vector<std::string> calls() const {
    std::vector<std::string> lines;
    std::istringstream in(slurp(bin / "calls.log"));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
};

/// `mcfbench submit ARGS` in `cwd` with the fakes first on PATH.
Command submit(const std::string& args, const fs::path& cwd, const FakeSlurm& fake) {
  return mcfbench("submit " + args, cwd, "PATH='" + fake.bin.string() + "':\"$PATH\" ");
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SlurmScript, ShellQuotingAndArraySpecs) {
  EXPECT_EQ(shell_quote("/a/b-c_d.json"), "/a/b-c_d.json");
  EXPECT_EQ(shell_quote("/a/b c"), "'/a/b c'");
  EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
  EXPECT_EQ(shell_quote("$HOME"), "'$HOME'");
  EXPECT_EQ(shell_quote(""), "''");
  EXPECT_EQ(shell_join({"a", "b c"}), "a 'b c'");
  EXPECT_EQ(array_spec({0, 1, 2}), "0-2");
  EXPECT_EQ(array_spec({1, 4, 5, 6, 9}), "1,4-6,9");
  EXPECT_EQ(array_spec({3}), "3");
}

TEST(SlurmScript, ScriptsSayWhatTheyRunWithEveryPathQuoted) {
  const fs::path dir = fresh_dir("scripts");
  BatchScriptInput in;
  in.study = "my study";
  in.quick = true;
  in.mcfbench = "/opt/mcf bench/mcfbench";
  in.config = "/home/u/it's/cfg.json";
  in.out_dir = "/scratch/u/100% done/out";
  in.cells = 10;
  in.tasks = 4;
  in.array = {0, 2, 3};
  in.report_script = "/src/reports/make_report.py";
  in.resubmit = "mcfbench submit x";
  in.job = {"short", "1:00:00", "4G", 2};
  const std::string run = run_array_script(in);
  for (const char* line :
       {"#SBATCH --job-name=mcfbench-my_study\n", "#SBATCH --array=0,2-3\n",
        "#SBATCH --cpus-per-task=2\n", "#SBATCH --partition=short\n", "#SBATCH --time=1:00:00\n",
        "#SBATCH --mem=4G\n",
        // '%' is Slurm's escape in file name patterns; the space needs the quotes.
        "#SBATCH --output=\"/scratch/u/100%% done/out/slurm/logs/run-%A_%a.out\"\n",
        "exec '/opt/mcf bench/mcfbench' run '/home/u/it'\\''s/cfg.json' --quick --out "
        "'/scratch/u/100% done/out'",
        "--shard \"${SLURM_ARRAY_TASK_ID:?submit this script with sbatch}/4\"",
        "--threads \"${SLURM_CPUS_PER_TASK:-2}\""})
    EXPECT_TRUE(contains(run, line)) << line << "\nnot in\n" << run;
  // sbatch reads #SBATCH lines up to the first command only.
  EXPECT_LT(run.rfind("#SBATCH"), run.find("\nset -eu"));
  EXPECT_FALSE(contains(run, "--ntasks"));  // one task: Slurm's default, no line
  in.job.ntasks = 4;                        // cells that run their solve on 4 MPI ranks
  const std::string ranked = run_array_script(in);
  EXPECT_TRUE(contains(ranked, "#SBATCH --ntasks=4\n")) << ranked;
  EXPECT_FALSE(contains(ranked, "--nodes"));  // Slurm's choice unless asked
  EXPECT_LT(ranked.rfind("#SBATCH"), ranked.find("\nset -eu"));
  in.job.nodes = 2;  // a flow divided over two nodes' memory
  const std::string spread = run_array_script(in);
  EXPECT_TRUE(contains(spread, "#SBATCH --nodes=2\n")) << spread;
  EXPECT_LT(spread.rfind("#SBATCH"), spread.find("\nset -eu"));
  in.job.nodes = 0;
  in.job.ntasks = 1;
  in.with_reference = true;
  const std::string collect = collect_script(in);
  for (const char* line :
       {"#SBATCH --job-name=mcfbench-my_study-collect\n",
        "#SBATCH --output=\"/scratch/u/100%% done/out/slurm/logs/collect-%j.out\"\n",
        "--threads \"${SLURM_CPUS_PER_TASK:-2}\" --distances-only || status=1\n",
        "'/opt/mcf bench/mcfbench' collect '/scratch/u/100% done/out' || complete=no\n",
        "/usr/bin/python3 /src/reports/make_report.py '/scratch/u/100% done/out' "
        "'/scratch/u/100% done/out/report' || status=1\n",
        "echo '  mcfbench submit x' >&2\n"})
    EXPECT_TRUE(contains(collect, line)) << line << "\nnot in\n" << collect;
  EXPECT_FALSE(contains(collect, "#SBATCH --array"));
  EXPECT_LT(collect.rfind("#SBATCH"), collect.find("\nset -u"));
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"run.sbatch", run}, {"collect.sbatch", collect}}) {
    write_text(dir / name, text);
    EXPECT_TRUE(bash_parses(dir / name)) << text;
  }
  // Without a reference flow there are no distances to add; without a report script, no report.
  in.with_reference = false;
  in.report_script.clear();
  const std::string plain = collect_script(in);
  EXPECT_FALSE(contains(plain, "--distances-only"));
  EXPECT_FALSE(contains(plain, "make_report"));
}

TEST(SlurmScript, AFolderAnSbatchLineCannotCarryIsRefused) {
  BatchScriptInput in;
  in.study = "s";
  in.mcfbench = "/b/mcfbench";
  in.config = "/c.json";
  in.array = {0};
  for (const char* out : {"/a\"b", "/a\\b", "/a\nb"}) {
    in.out_dir = out;
    EXPECT_THROW(run_array_script(in), std::invalid_argument) << out;
    EXPECT_THROW(collect_script(in), std::invalid_argument) << out;
  }
}

TEST(SlurmSubmit, RequestsAreCheckedBeforeAnythingHappens) {
  SubmitRequest ok;
  ok.config = "c.json";
  ok.out = "out";
  ok.sbatch_args = {"--account=proj", "-Aproj", "--qos=low", "--exclusive", "--cpus-per-gpu=2"};
  EXPECT_NO_THROW(check_submit_request(ok));
  const std::vector<std::pair<std::vector<std::string>, std::string>> refused = {
      {{"--array=0-3"}, "--array"},      {{"--arr=0-3"}, "--array"},
      {{"-a", "0-3"}, "--array"},        {{"--dependency=afterok:1"}, "--dependency"},
      {{"-dafterok:1"}, "--dependency"}, {{"--cpus-per-task=4"}, "--cpus-per-task"},
      {{"-c4"}, "--cpus-per-task"},      {{"--parsable"}, "--parsable"},
      {{"--wrap=echo hi"}, "--wrap"},    {{"--account", "proj"}, "one word each"},
      {{"job.sh"}, "one word each"},
  };
  for (const auto& [args, message] : refused) {
    SubmitRequest r = ok;
    r.sbatch_args = args;
    try {
      check_submit_request(r);
      ADD_FAILURE() << args[0] << ": accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_TRUE(contains(e.what(), message)) << e.what();
      // Names the argument at fault (the first that is).
      EXPECT_TRUE(std::any_of(args.begin(), args.end(), [&](const std::string& a) {
        return contains(e.what(), "\"" + a + "\"");
      })) << e.what();
    }
  }
  SubmitRequest r = ok;
  r.out.clear();
  EXPECT_THROW(check_submit_request(r), std::invalid_argument);
  r = ok;
  r.tasks = -1;
  EXPECT_THROW(check_submit_request(r), std::invalid_argument);
  r = ok;
  r.cpus_per_task = 0;
  EXPECT_THROW(check_submit_request(r), std::invalid_argument);
}

TEST(SubmitCli, DryRunWritesScriptsThatRunTheStudyAndSubmitsNothing) {
  const fs::path dir = fresh_dir("dry_run");
  FakeSlurm fake(dir);
  write_text(dir / "tiny.json", tiny_reference_config);
  const fs::path out = dir / "it's a results folder";
  const Command c =
      submit("tiny.json --out \"it's a results folder\" --tasks 3 --dry-run", dir, fake);
  ASSERT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_TRUE(contains(c.out, "dry run: nothing submitted")) << c.out;
  EXPECT_TRUE(contains(c.out, "3 cells, 0 finished, 3 to run in 3 of 3 tasks")) << c.out;
  EXPECT_TRUE(fake.calls().empty()) << slurp(fake.bin / "calls.log");
  EXPECT_FALSE(fs::exists(out / "slurm" / "submitted.json"));
  const fs::path run = out / "slurm" / "run.sbatch", collect = out / "slurm" / "collect.sbatch";
  ASSERT_TRUE(fs::exists(run) && fs::exists(collect));
  EXPECT_TRUE(fs::is_directory(out / "slurm" / "logs"));  // sbatch would not create it
  EXPECT_TRUE(contains(slurp(run), "#SBATCH --array=0-2\n")) << slurp(run);
  EXPECT_TRUE(contains(slurp(run), (dir / "tiny.json").string())) << "config path not absolute";
  EXPECT_TRUE(bash_parses(run));
  EXPECT_TRUE(bash_parses(collect));

  // The scripts as the scheduler would run them: three tasks, then the collect job.
  const std::string in_dir = "cd '" + dir.string() + "' && ";
  Command before = mcfbench("collect \"it's a results folder\" --out before.json", dir);
  EXPECT_NE(before.status, 0);         // nothing there yet
  fs::copy_file(run, dir / "run.sh");  // its path holds a quote
  for (int task = 0; task < 3; ++task) {
    const std::string cmd = in_dir + "SLURM_ARRAY_TASK_ID=" + std::to_string(task) +
                            " SLURM_CPUS_PER_TASK=1 bash run.sh >task.log 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "task.log");
  }
  EXPECT_EQ(result_files(out).size(), 3u);
  if (!has_matplotlib()) GTEST_SKIP() << "the collect script's report needs matplotlib";
  fs::copy_file(collect, dir / "collect.sh");  // its path holds a quote
  const std::string cmd = in_dir + "bash collect.sh >collect.log 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(dir / "collect.log");
  EXPECT_TRUE(contains(slurp(dir / "collect.log"), "3 cells found of 3, 0 missing"))
      << slurp(dir / "collect.log");
  EXPECT_TRUE(fs::exists(out / "report" / "index.md"));
  EXPECT_TRUE(fs::exists(out / "index.json"));
}

TEST(SubmitCli, SubmitsTheArrayThenTheCollectJobDependingOnIt) {
  const fs::path dir = fresh_dir("submit");
  FakeSlurm fake(dir);
  write_text(dir / "tiny.json", tiny_reference_config);
  const Command c = submit(
      "tiny.json --quick --out out --cpus-per-task 2 --partition short --time 5:00 --mem 1G "
      "-- --account=proj --qos=low",
      dir, fake);
  // --quick on a config without a quick variant is refused, before anything is written.
  EXPECT_NE(c.status, 0);
  EXPECT_TRUE(contains(c.err, "quick")) << c.err;
  EXPECT_FALSE(fs::exists(dir / "out"));

  const Command ok = submit(
      "tiny.json --out out --cpus-per-task 2 --partition short --time 5:00 --mem 1G "
      "-- --account=proj --qos=low",
      dir, fake);
  ASSERT_EQ(ok.status, 0) << ok.out << ok.err;
  const std::string run = (dir / "out" / "slurm" / "run.sbatch").string();
  const std::string collect = (dir / "out" / "slurm" / "collect.sbatch").string();
  const std::vector<std::string> calls = fake.calls();
  ASSERT_EQ(calls.size(), 2u) << slurp(fake.bin / "calls.log");
  EXPECT_EQ(calls[0], "sbatch [--parsable] [--account=proj] [--qos=low] [" + run + "]");
  EXPECT_EQ(calls[1],
            "sbatch [--parsable] [--dependency=afterany:4241] [--account=proj] "
            "[--qos=low] [" +
                collect + "]");
  // One task per cell by default; every job with the resources asked for.
  const std::string script = slurp(run);
  for (const char* line :
       {"#SBATCH --array=0-2\n", "#SBATCH --cpus-per-task=2\n", "#SBATCH --partition=short\n",
        "#SBATCH --time=5:00\n", "#SBATCH --mem=1G\n", "--shard \"${SLURM_ARRAY_TASK_ID:?"})
    EXPECT_TRUE(contains(script, line)) << line << " not in\n" << script;
  EXPECT_TRUE(contains(slurp(collect), "#SBATCH --partition=short\n"));
  const json record = read_json(dir / "out" / "slurm" / "submitted.json");
  EXPECT_EQ(record["array_job"], "4241");
  EXPECT_EQ(record["collect_job"], "4242");
  EXPECT_EQ(record["array"], "0-2");
  EXPECT_EQ(record["cpus_per_task"], 2);
  EXPECT_TRUE(contains(record["command"], "--account=proj")) << record.dump();
  EXPECT_TRUE(contains(ok.out, "squeue --jobs=4241,4242")) << ok.out;
  EXPECT_TRUE(contains(ok.out, "sacct --jobs=4241,4242")) << ok.out;
}

TEST(SubmitCli, BadArgumentsAreRefusedBeforeAnythingIsWritten) {
  const fs::path dir = fresh_dir("bad_args");
  FakeSlurm fake(dir);
  write_text(dir / "tiny.json", tiny_reference_config);
  write_text(dir / "bad.json", R"({"defaults": {"mesh": "icosphere:level=1", "stpes": 2}})");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"tiny.json --out out --tasks 0", "--tasks"},
      {"tiny.json --out out --cpus-per-task 0", "--cpus-per-task"},
      {"tiny.json --tasks 2", "--out"},
      {"tiny.json --out out --bogus", "--bogus"},
      {"tiny.json --out out -- --array=0-9", "--array"},
      {"tiny.json --out out -- -c 4", "--cpus-per-task"},
      {"tiny.json --out out -- job.sh", "one word each"},
      {"bad.json --out out", "defaults.stpes"},
      {"missing.json --out out", "missing.json"},
  };
  for (const auto& [args, message] : cases) {
    const Command c = submit(args, dir, fake);
    EXPECT_NE(c.status, 0) << args;
    EXPECT_TRUE(contains(c.err + c.out, message)) << args << ": " << c.err << c.out;
    EXPECT_FALSE(fs::exists(dir / "out")) << args << ": wrote the results folder";
  }
  // A folder an #SBATCH line cannot name.
  const Command c = submit("tiny.json --out 'say \"hi\"'", dir, fake);
  EXPECT_NE(c.status, 0);
  EXPECT_TRUE(contains(c.err, "#SBATCH")) << c.err;
  EXPECT_FALSE(fs::exists(dir / "say \"hi\""));
  EXPECT_TRUE(fake.calls().empty()) << slurp(fake.bin / "calls.log");
}

TEST(SubmitCli, ARefusingSbatchIsShownAsItIsAndNothingStaysSubmitted) {
  const fs::path dir = fresh_dir("sbatch_fails");
  FakeSlurm fake(dir);
  write_text(dir / "tiny.json", tiny_reference_config);
  const std::string message =
      "sbatch: error: invalid partition specified: nosuch\n"
      "sbatch: error: Batch job submission failed: Invalid partition name specified\n";
  write_text(fake.bin / "message", message);
  write_text(fake.bin / "fail_at", "1\n");
  Command c = submit("tiny.json --out out --partition nosuch", dir, fake);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_TRUE(contains(c.err, message)) << c.err;
  EXPECT_TRUE(contains(c.err, "nothing was submitted")) << c.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "slurm" / "submitted.json"));
  ASSERT_EQ(fake.calls().size(), 1u) << slurp(fake.bin / "calls.log");

  // The array submitted, its collect job refused: the array is cancelled.
  fs::remove(fake.bin / "calls.log");
  fs::remove(fake.bin / "count");
  write_text(fake.bin / "fail_at", "2\n");
  c = submit("tiny.json --out out", dir, fake);
  EXPECT_EQ(c.status, 1) << c.out << c.err;
  EXPECT_TRUE(contains(c.err, message)) << c.err;
  EXPECT_TRUE(contains(c.err, "cancelled job(s) 4241")) << c.err;
  const std::vector<std::string> calls = fake.calls();
  ASSERT_EQ(calls.size(), 3u) << slurp(fake.bin / "calls.log");
  EXPECT_EQ(calls[2], "scancel [4241]");
  EXPECT_FALSE(fs::exists(dir / "out" / "slurm" / "submitted.json"));

  // No sbatch at all.
  const std::string cmd = "cd '" + dir.string() + "' && PATH=/nonexistent " + MCFBENCH_BINARY +
                          " submit tiny.json --out out >o.txt 2>e.txt";
  EXPECT_NE(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(contains(slurp(dir / "e.txt"), "cannot run sbatch")) << slurp(dir / "e.txt");
}

TEST(SubmitCli, ASecondSubmissionRunsOnlyTheShardsWithCellsLeft) {
  const fs::path dir = fresh_dir("resubmit");
  FakeSlurm fake(dir);
  write_text(dir / "tiny.json", tiny_reference_config);
  ASSERT_EQ(submit("tiny.json --out out", dir, fake).status, 0);
  // While the first submission's jobs are queued, a second one is refused.
  write_text(fake.bin / "queue", "4241_[1-2]\n4241_0\n4242\n");
  Command c = submit("tiny.json --out out", dir, fake);
  EXPECT_EQ(c.status, 1);
  EXPECT_TRUE(contains(c.err, "4241, 4242 of the previous submission")) << c.err;
  EXPECT_TRUE(contains(c.err, "still queued or running")) << c.err;
  EXPECT_EQ(fake.calls().size(), 3u) << "sbatch ran: " << slurp(fake.bin / "calls.log");
  // The array ran cell 1 only (its other tasks lost), as its task would: one thread.
  write_text(fake.bin / "queue", "9999\n");
  const Command shard = mcfbench("run tiny.json --out out --shard 1/3 --threads 1", dir);
  ASSERT_EQ(shard.status, 0) << shard.err;
  c = submit("tiny.json --out out", dir, fake);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(contains(c.out, "3 cells, 1 finished, 2 to run in 2 of 3 tasks")) << c.out;
  EXPECT_TRUE(contains(slurp(dir / "out" / "slurm" / "run.sbatch"), "#SBATCH --array=0,2\n"));
  EXPECT_EQ(read_json(dir / "out" / "slurm" / "submitted.json")["array"], "0,2");
  // Another thread count would give every cell another key: refused.
  c = submit("tiny.json --out out --cpus-per-task 4", dir, fake);
  EXPECT_NE(c.status, 0);
  EXPECT_TRUE(contains(c.err, "--cpus-per-task 1")) << c.err;
  // Everything finished: only the collect job, without a dependency.
  for (const char* s : {"0/3", "2/3"})
    ASSERT_EQ(mcfbench(std::string("run tiny.json --out out --threads 1 --shard ") + s, dir).status,
              0);
  fs::remove(fake.bin / "calls.log");
  c = submit("tiny.json --out out", dir, fake);
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_TRUE(contains(c.out, "all 3 cells are finished")) << c.out;
  const std::vector<std::string> calls = fake.calls();
  ASSERT_EQ(calls.size(), 2u) << slurp(fake.bin / "calls.log");  // squeue, then sbatch
  EXPECT_EQ(calls[1],
            "sbatch [--parsable] [" + (dir / "out" / "slurm" / "collect.sbatch").string() + "]");
  const json record = read_json(dir / "out" / "slurm" / "submitted.json");
  EXPECT_TRUE(record["array"].is_null());
  EXPECT_EQ(record["array_job"], "");
}

}  // namespace
}  // namespace mcf
