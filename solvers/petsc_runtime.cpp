#include "solvers/petsc_runtime.h"

#include <cstdlib>
#include <mutex>

#ifdef MCFBENCH_HAVE_PETSC
#include <petscsys.h>
#endif

namespace mcf {

std::string petsc_unavailable_message() {
  return "this mcfbench was built without PETSc; install it (Debian: apt-get install "
         "libpetsc-real-dev openmpi-bin, which scripts/setup.sh does) and reconfigure "
         "(cmake -DMCFBENCH_PETSC=AUTO or ON, then rebuild)";
}

int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* value = std::getenv(name)) {
      const int n = std::atoi(value);
      if (n > 0) return n;
    }
  return 1;
}

int launched_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK"})
    if (const char* value = std::getenv(name)) {
      const int n = std::atoi(value);
      if (n >= 0) return n;
    }
  return 0;
}

#ifndef MCFBENCH_HAVE_PETSC

bool petsc_available() {
  return false;
}
PetscRuntime& PetscRuntime::instance() {
  throw PetscUnavailable(petsc_unavailable_message());
}
PetscRuntime::PetscRuntime() = default;
PetscRuntime::~PetscRuntime() = default;
std::string PetscRuntime::new_prefix() {
  return "mcf" + std::to_string(++next_prefix_) + "_";
}
std::string PetscRuntime::version() const {
  return "";
}
void petsc_check(int code, const char* what) {
  if (code != 0) throw PetscFailure(std::string(what) + " failed");
}

#else

namespace {
// PETSc keeps the argv it is given for the whole session; the flags go in as if on the command
// line, where the options database reads them before anything else does:
// -no_signal_handler: SIGINT/SIGTERM stay the harness's (a stopped flow writes its result file),
// -options_left 0: PetscFinalize does not list options a validation trial left unused.
char arg0[] = "mcfbench";
char arg1[] = "-no_signal_handler";
char arg2[] = "-options_left";
char arg3[] = "0";
char* petsc_argv_storage[] = {arg0, arg1, arg2, arg3, nullptr};
int petsc_argc = 4;
char** petsc_argv = petsc_argv_storage;
}  // namespace

bool petsc_available() {
  return true;
}

void petsc_check(int code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  char* specific = nullptr;
  PetscErrorMessage(code, &text, &specific);
  std::string message = std::string(what) + ": ";
  if (specific != nullptr && specific[0] != '\0')
    message += specific;
  else if (text != nullptr)
    message += text;
  else
    message += "PETSc error " + std::to_string(code);
  // PETSc's messages end in a newline.
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  throw PetscFailure(message);
}

PetscRuntime::PetscRuntime() {
  petsc_check(PetscInitialize(&petsc_argc, &petsc_argv, nullptr, nullptr), "PetscInitialize");
  // Errors return their codes (petsc_check turns them into exceptions) instead of printing a
  // traceback to stderr and, in places, aborting.
  petsc_check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
  MPI_Comm_size(PETSC_COMM_WORLD, &size_);
}

PetscRuntime::~PetscRuntime() {
  PetscFinalize();
}

PetscRuntime& PetscRuntime::instance() {
  static PetscRuntime runtime;  // thread-safe start; destroyed (finalized) at exit
  return runtime;
}

std::string PetscRuntime::new_prefix() {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  return "mcf" + std::to_string(++next_prefix_) + "_";
}

std::string PetscRuntime::version() const {
  return "PETSc " + std::to_string(PETSC_VERSION_MAJOR) + "." +
         std::to_string(PETSC_VERSION_MINOR) + "." + std::to_string(PETSC_VERSION_SUBMINOR);
}

#endif

}  // namespace mcf
