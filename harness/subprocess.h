#pragma once
// Running another program to its end (the scheduler's commands: sbatch, squeue, scancel): its
// standard output is captured for the caller to parse, its standard error goes where this
// process's goes, so the program's own messages reach the user as it wrote them.

#include <string>
#include <vector>

namespace mcf {

struct ProgramResult {
  /// The exit status; 128 + N when signal N ended it; -1 when it could not be started.
  int status = -1;
  std::string out;          ///< what it wrote on its standard output
  std::string start_error;  ///< why it could not be started ("No such file or directory")
  bool ok() const { return status == 0; }
};

/// Runs argv[0], looked up on PATH, with the arguments argv[1..]: standard input /dev/null,
/// standard output captured, standard error shared. Waits for it to end. Never throws for the
/// program's failure (the answer says it); throws std::invalid_argument for an empty argv.
/// With `startup_environment`, the program gets this process's environment as it was when the
/// process started, without what was set since (MPI's singleton start sets variables that would
/// make an mpirun started from here take itself for a part of this process's job).
ProgramResult run_program(const std::vector<std::string>& argv, bool startup_environment = false);

}  // namespace mcf
