// register_preconditioner from the outside: a row added at run time is a value of
// `solver.preconditioner` that CG runs with, and a row the table cannot take is refused.

#include "config/preconditioner_registry.h"
#include "flow_test_util.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace mcf {
namespace {

PreconditionerRow jacobi_under(const std::string& name) {
  PreconditionerRow row = preconditioner_row("jacobi");
  row.name = name;
  row.help = "the inverse diagonal, registered again by a test";
  return row;
}

TEST(PreconditionerRegistry, ARegisteredRowPreconditionsCgAsTheRowItWraps) {
  register_preconditioner(jacobi_under("test-jacobi"));
  const nlohmann::json base = {
      {"mesh", "icosphere:level=3"}, {"flow", "mcf"}, {"dt", 1e-3}, {"steps", 3}, {"threads", 1}};
  nlohmann::json mine = base, jacobi = base;
  mine["solver"] = {{"name", "pcg"}, {"preconditioner", "test-jacobi"}};
  jacobi["solver"] = {{"name", "pcg"}, {"preconditioner", "jacobi"}};
  const FlowOutcome a = testing::run(mine), b = testing::run(jacobi);
  ASSERT_EQ(a.result["status"], "ok");
  EXPECT_EQ(a.result["config"]["solver"]["preconditioner"], "test-jacobi");
  EXPECT_EQ(a.final_mesh.vertices, b.final_mesh.vertices);
  EXPECT_EQ(a.result["steps"].back()["solver"]["iterations"],
            b.result["steps"].back()["solver"]["iterations"]);
}

TEST(PreconditionerRegistry, RefusesARowWithoutFactoryOrMemoryModelOrATakenName) {
  PreconditionerRow no_make = jacobi_under("test-no-make");
  no_make.make = nullptr;
  EXPECT_THROW(register_preconditioner(no_make), std::logic_error);
  PreconditionerRow no_memory = jacobi_under("test-no-memory");
  no_memory.memory = nullptr;
  EXPECT_THROW(register_preconditioner(no_memory), std::logic_error);
  EXPECT_THROW(register_preconditioner(jacobi_under("jacobi")), std::logic_error);
  EXPECT_THROW(preconditioner_row("test-no-memory"), std::exception);
}

}  // namespace
}  // namespace mcf
