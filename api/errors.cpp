#include "api/detail.h"

#include "datasets/mesh_error.h"
#include "flows/config_reader.h"

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

}  // namespace detail
}  // namespace mcfbench
