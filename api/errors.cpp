#include "api/detail.h"

#include "config/config_reader.h"
#include "datasets/mesh_error.h"

#include <exception>
#include <stdexcept>

namespace mcfbench {

InputError::InputError(const std::string& what) : std::invalid_argument(what) {}
InputError::~InputError() = default;

namespace detail {

void rethrow_as_input_error() {
  try {
    throw;
  } catch (const mcf::ConfigError& e) {
    throw InputError(e.what());
  } catch (const mcf::MeshError& e) {
    throw InputError(e.what());
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  // Anything else (a caller's exception, std::runtime_error) leaves the catch above unchanged.
}

std::mutex& run_lock() {
  static std::mutex lock;
  return lock;
}

namespace {
thread_local bool running_here = false;
}  // namespace

RunScope::RunScope(const std::string& what) {
  if (running_here)
    throw InputError(what +
                     ": called from inside a running flow or study (its callback or a "
                     "registered solver); one runs at a time per process");
  lock_ = std::unique_lock<std::mutex>(run_lock());
  running_here = true;
}

RunScope::~RunScope() {
  running_here = false;
}

bool RunScope::inside() {
  return running_here;
}

}  // namespace detail
}  // namespace mcfbench
