# Every dependency comes from a Debian 12 package, found with find_package (no downloads).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(ZLIB REQUIRED)  # compressed VTK output

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
