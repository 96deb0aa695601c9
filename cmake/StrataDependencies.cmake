# Every dependency comes from a Debian 12 package, found with find_package (no downloads).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(ZLIB REQUIRED)  # reading compressed VTK files

# libdeflate (libdeflate-dev) writes the compressed VTK frames: zlib streams, 2–3 times faster
# than zlib's own level 1. Only a pkg-config file: an interface target from find_path/find_library.
find_path(LIBDEFLATE_INCLUDE_DIR libdeflate.h)
find_library(LIBDEFLATE_LIBRARY deflate)
if(NOT LIBDEFLATE_INCLUDE_DIR OR NOT LIBDEFLATE_LIBRARY)
  message(FATAL_ERROR "libdeflate not found: install libdeflate-dev")
endif()
if(NOT TARGET strata_libdeflate)
  add_library(strata_libdeflate INTERFACE)
  target_include_directories(strata_libdeflate SYSTEM INTERFACE ${LIBDEFLATE_INCLUDE_DIR})
  target_link_libraries(strata_libdeflate INTERFACE ${LIBDEFLATE_LIBRARY})
endif()

# SuiteSparse 5.x ships no CMake or pkg-config file: an imported target from find_path/find_library.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
if(NOT CHOLMOD_INCLUDE_DIR OR NOT CHOLMOD_LIBRARY)
  message(FATAL_ERROR "CHOLMOD not found: install libsuitesparse-dev")
endif()
if(NOT TARGET strata_cholmod)
  add_library(strata_cholmod INTERFACE)
  target_include_directories(strata_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
  target_link_libraries(strata_cholmod INTERFACE ${CHOLMOD_LIBRARY})
endif()

# hypre (BoomerAMG, libhypre-dev) ships no CMake file either; Debian builds it on Open MPI, whose
# C interface it needs (called from C++, without the deprecated C++ bindings).
set(MPI_CXX_SKIP_MPICXX TRUE)
find_package(MPI REQUIRED COMPONENTS CXX)
find_path(HYPRE_INCLUDE_DIR HYPRE.h PATH_SUFFIXES hypre)
find_library(HYPRE_LIBRARY HYPRE)
if(NOT HYPRE_INCLUDE_DIR OR NOT HYPRE_LIBRARY)
  message(FATAL_ERROR "hypre not found: install libhypre-dev")
endif()
if(NOT TARGET strata_hypre)
  add_library(strata_hypre INTERFACE)
  target_include_directories(strata_hypre SYSTEM INTERFACE ${HYPRE_INCLUDE_DIR})
  target_link_libraries(strata_hypre INTERFACE ${HYPRE_LIBRARY} MPI::MPI_CXX)
endif()
