#pragma once
// MCFBENCH_API marks what libmcfbench exports. The library is built with hidden visibility and
// everything of the harness below its public API stays inside it, so a program links against
// these functions and types only.

#if defined(_WIN32)
#define MCFBENCH_API
#else
#define MCFBENCH_API __attribute__((visibility("default")))
#endif
