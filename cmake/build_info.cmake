# Runs at every build (not only at configure): the commit baked into results must be the one
# the binary was built from. Rewrites the header only when it changes, so nothing rebuilds.
execute_process(COMMAND git rev-parse --short=12 HEAD WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE MCFBENCH_GIT_COMMIT OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
execute_process(COMMAND git status --porcelain --untracked-files=no WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE _dirty OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT MCFBENCH_GIT_COMMIT)
  set(MCFBENCH_GIT_COMMIT "unknown")
elseif(_dirty)
  # The uncommitted change's own fingerprint, so two different edits of one commit never share
  # a label: result cells are keyed by it, and a run resumed after an edit must not take the
  # cells of the earlier edit for its own (benchmarks/run_micro.sh names its files the same way).
  execute_process(COMMAND git diff HEAD WORKING_DIRECTORY ${SOURCE_DIR}
                  OUTPUT_VARIABLE _diff ERROR_QUIET)
  string(SHA1 _diff_hash "${_diff}")
  string(SUBSTRING "${_diff_hash}" 0 8 _diff_hash)
  set(MCFBENCH_GIT_COMMIT "${MCFBENCH_GIT_COMMIT}-dirty-${_diff_hash}")
endif()
# Flags that change the generated code, as JSON booleans.
if(MCFBENCH_NATIVE)
  set(MCFBENCH_NATIVE_JSON true)
else()
  set(MCFBENCH_NATIVE_JSON false)
endif()
if(MCFBENCH_SANITIZE)
  set(MCFBENCH_SANITIZE_JSON true)
else()
  set(MCFBENCH_SANITIZE_JSON false)
endif()
configure_file(${SOURCE_DIR}/cmake/build_info.h.in ${OUTPUT}.tmp @ONLY)
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different ${OUTPUT}.tmp ${OUTPUT})
file(REMOVE ${OUTPUT}.tmp)
