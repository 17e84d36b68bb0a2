// register_basis from the outside: a row added at run time is a value of `basis` that flows run
// with, and a row the table cannot take is refused.

#include "config/basis_registry.h"
#include "flow_test_util.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mcf {
namespace {

// The hat basis under another name: the same factory, memory model and capabilities.
BasisRow hat_under(const std::string& name) {
  BasisRow row = basis_row("hat");
  row.name = name;
  row.help = "the hat basis, registered again by a test";
  return row;
}

TEST(BasisRegistry, ARegisteredRowFlowsAsTheRowItWraps) {
  register_basis(hat_under("test-hat"));
  EXPECT_EQ(&basis_row("test-hat"), &basis_row("test-hat"));
  const nlohmann::json base = {
      {"mesh", "icosphere:level=3"}, {"flow", "mcf"}, {"dt", 1e-3}, {"steps", 3}, {"threads", 1}};
  nlohmann::json mine = base, hat = base;
  mine["basis"] = "test-hat";
  hat["basis"] = "hat";
  const FlowOutcome a = testing::run(mine), b = testing::run(hat);
  ASSERT_EQ(a.result["status"], "ok");
  EXPECT_EQ(a.result["config"]["basis"], "test-hat");
  EXPECT_EQ(a.final_mesh.vertices, b.final_mesh.vertices);  // the same code: the same bits
}

TEST(BasisRegistry, RefusesARowWithoutFactoryOrMemoryModelOrATakenName) {
  BasisRow no_make = hat_under("test-no-make");
  no_make.make = nullptr;
  EXPECT_THROW(register_basis(no_make), std::logic_error);
  BasisRow no_memory = hat_under("test-no-memory");
  no_memory.memory = nullptr;
  EXPECT_THROW(register_basis(no_memory), std::logic_error);
  EXPECT_THROW(register_basis(hat_under("hat")), std::logic_error);
  EXPECT_THROW(basis_row("test-no-memory"), std::exception);  // nothing half-registered
}

}  // namespace
}  // namespace mcf
