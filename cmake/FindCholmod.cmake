# Debian 12's SuiteSparse ships no CMake config for CHOLMOD: locate header and library by hand,
# and link OpenBLAS (CHOLMOD's supernodal factorization is 3-4x slower on the reference BLAS).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
find_library(OPENBLAS_LIBRARY openblas REQUIRED)
add_library(Cholmod::Cholmod INTERFACE IMPORTED)
target_include_directories(Cholmod::Cholmod INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(Cholmod::Cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY} ${OPENBLAS_LIBRARY})
message(STATUS "CHOLMOD: ${CHOLMOD_LIBRARY} (BLAS: ${OPENBLAS_LIBRARY})")
