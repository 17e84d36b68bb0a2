# PETSc through pkg-config (Debian's libpetsc-real-dev ships PETSc.pc; its flags leave out MPI's
# headers, so MPI's C interface comes from its own pkg-config file, mpi-c, which Open MPI ships:
# CMake's FindMPI would need the C language enabled). Sets MCFBENCH_HAVE_PETSC and, when true, the
# targets PkgConfig::PETSC and PkgConfig::MPI_C. MCFBENCH_PETSC: AUTO (use it where found), ON
# (required), OFF (not used).
set(MCFBENCH_HAVE_PETSC OFF)
if(NOT MCFBENCH_PETSC STREQUAL "OFF")
  find_package(PkgConfig)
  if(PkgConfig_FOUND)
    pkg_check_modules(PETSC IMPORTED_TARGET PETSc)
  endif()
  if(PETSC_FOUND)
    pkg_check_modules(MPI_C IMPORTED_TARGET mpi-c)
  endif()
  if(PETSC_FOUND AND MPI_C_FOUND)
    set(MCFBENCH_HAVE_PETSC ON)
    message(STATUS "PETSc: ${PETSC_VERSION} (${PETSC_LIBRARY_DIRS}); MPI: ${MPI_C_LINK_LIBRARIES}")
  elseif(MCFBENCH_PETSC STREQUAL "ON")
    message(FATAL_ERROR "MCFBENCH_PETSC=ON but PETSc (pkg-config PETSc) with MPI was not found: "
                        "apt-get install libpetsc-real-dev openmpi-bin")
  else()
    message(STATUS "PETSc: not found; --solver petsc is refused (apt-get install libpetsc-real-dev)")
  endif()
else()
  message(STATUS "PETSc: off (MCFBENCH_PETSC=OFF); --solver petsc is refused")
endif()
