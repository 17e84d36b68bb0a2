#pragma once
// mcfbench's public C++ API: meshes, bases and their operators, solvers (built-in and your own),
// flows step by step, experiments and their results (docs/library.md). Link mcfbench::mcfbench:
//
//   find_package(mcfbench REQUIRED)
//   target_link_libraries(app PRIVATE mcfbench::mcfbench)

#include "mcfbench/basis.h"
#include "mcfbench/flow.h"
#include "mcfbench/mesh.h"
#include "mcfbench/solver.h"
#include "mcfbench/study.h"
#include "mcfbench/types.h"
