#pragma once
// The process's PETSc session (docs/petsc.md): PetscInitialize on first use, PetscFinalize when
// the process exits, never more than once each (PETSc, and the MPI it starts, cannot be started
// again once finalized). Only a `--solver petsc` run starts it, so a run of any other solver
// never initializes MPI. Without PETSc in the build (CMake's MCFBENCH_PETSC) every call that
// would need it throws PetscUnavailable, whose message says how to install it.

#include <stdexcept>
#include <string>

namespace mcf {

struct PetscUnavailable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A PETSc call that failed: its error message (PETSc's own text, e.g. "Unknown type. Check for
/// miss-spelling or missing package: ... KSP type foo") and where.
struct PetscFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Whether this build has PETSc.
bool petsc_available();

/// Why `--solver petsc` is refused in a build without PETSc, and how to get it.
std::string petsc_unavailable_message();

class PetscRuntime {
 public:
  /// The session, started on the first call: PetscInitialize (which starts MPI unless the
  /// process already did) with PETSc's signal handler off (the harness handles SIGINT/SIGTERM
  /// itself: harness/stop_signals.h) and its errors returned as codes instead of printed
  /// tracebacks, so a failed call becomes a PetscFailure with PETSc's message. Throws
  /// PetscUnavailable without PETSc, PetscFailure when the initialization fails.
  static PetscRuntime& instance();

  PetscRuntime(const PetscRuntime&) = delete;
  PetscRuntime& operator=(const PetscRuntime&) = delete;

  /// A prefix of the options database never handed out before in this process ("mcf1_",
  /// "mcf2_", ...): each solver inserts its options under its own, so two solvers' options never
  /// collide. Every MPI rank hands out the same sequence.
  std::string new_prefix();

  int rank() const { return rank_; }  ///< in PETSC_COMM_WORLD
  int size() const { return size_; }  ///< ranks in PETSC_COMM_WORLD
  /// "PETSc 3.18.5" (the library's own version string), for result.json's "libraries".
  std::string version() const;

 private:
  PetscRuntime();
  ~PetscRuntime();  // PetscFinalize, at exit (a function-local static)
  int next_prefix_ = 0;
  int rank_ = 0, size_ = 1;
};

/// The number of processes the MPI launcher started, read from its environment before MPI is
/// started (Open MPI's OMPI_COMM_WORLD_SIZE, MPICH's and Slurm's PMI_SIZE); 1 without a launcher.
int launched_ranks();
/// This process's rank as the launcher numbered it (OMPI_COMM_WORLD_RANK, PMI_RANK); 0 without
/// a launcher. Read before MPI starts (to print an error once, from rank 0).
int launched_rank();

/// Turns a PETSc error code into a PetscFailure naming `what` and PETSc's message (no-op on 0).
void petsc_check(int code, const char* what);

}  // namespace mcf
