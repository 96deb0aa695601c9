# Installation and package export: headers, the three shared libraries, the `strata` program, and
# a relocatable CMake package so another project can `find_package(strata)` and link strata::core,
# strata::hierarchy and strata::meshing.
#
# Installed layout under CMAKE_INSTALL_PREFIX:
#   include/strata/{core,hierarchy,meshing}/...     public headers
#   <libdir>/libstrata_{core,hierarchy,meshing}.so  shared libraries (RUNPATH $ORIGIN)
#   bin/strata                                      command-line program (RUNPATH $ORIGIN/../<libdir>)
#   <libdir>/cmake/strata/                          strataConfig.cmake, strataConfigVersion.cmake,
#                                                   strataTargets*.cmake
#
# Only Eigen is a public dependency (the headers use it). TBB, zlib, libdeflate, nlohmann_json,
# CHOLMOD and hypre (with Open MPI) are private link dependencies of the shared libraries and do not appear in the exported interface; the
# warning and tuning targets are BUILD_INTERFACE only.
include(CMakePackageConfigHelpers)
include(StrataEigenAbi)

set(STRATA_LIBRARY_TARGETS strata_core strata_hierarchy strata_meshing)
set(STRATA_CONFIG_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/strata)

# RUNPATH: libraries find each other beside themselves, programs find them in ../<libdir>.
set_target_properties(${STRATA_LIBRARY_TARGETS} PROPERTIES INSTALL_RPATH "$ORIGIN")

install(TARGETS ${STRATA_LIBRARY_TARGETS}
  EXPORT strataTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
          NAMELINK_COMPONENT development
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

foreach(module core hierarchy meshing)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT development
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()

# The command-line program `strata` is installed by experiments/cli/CMakeLists.txt (RUNPATH
# $ORIGIN/../<libdir>); install it here only if that file stops doing so.

install(EXPORT strataTargets
  NAMESPACE strata::
  DESTINATION ${STRATA_CONFIG_INSTALL_DIR}
  COMPONENT development)

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/strataConfig.cmake.in
  ${PROJECT_BINARY_DIR}/strataConfig.cmake
  INSTALL_DESTINATION ${STRATA_CONFIG_INSTALL_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/strataConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/strataConfig.cmake ${PROJECT_BINARY_DIR}/strataConfigVersion.cmake
  DESTINATION ${STRATA_CONFIG_INSTALL_DIR}
  COMPONENT development)
