# cmake -P script behind the `install_consumer` test (see CMakeLists.txt beside it).
# Inputs: STRATA_BUILD_DIR, STRATA_CONSUMER_SOURCE_DIR, STRATA_WORK_DIR, STRATA_CONFIG,
# STRATA_CXX_COMPILER.
cmake_minimum_required(VERSION 3.25)

foreach(var STRATA_BUILD_DIR STRATA_CONSUMER_SOURCE_DIR STRATA_WORK_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "run_install_test.cmake: ${var} is not set")
  endif()
endforeach()
if(NOT STRATA_CONFIG)
  set(STRATA_CONFIG Release)
endif()

set(prefix ${STRATA_WORK_DIR}/prefix)
set(consumer_build ${STRATA_WORK_DIR}/consumer-build)
file(REMOVE_RECURSE ${STRATA_WORK_DIR})
file(MAKE_DIRECTORY ${STRATA_WORK_DIR})

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("== ${step}\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${step} failed (${rc})")
  endif()
endfunction()

run("install" ${CMAKE_COMMAND} --install ${STRATA_BUILD_DIR} --prefix ${prefix}
    --config ${STRATA_CONFIG})

# The package files and headers are where the export says.
file(GLOB_RECURSE config_files ${prefix}/*/strataConfig.cmake)
file(GLOB_RECURSE version_files ${prefix}/*/strataConfigVersion.cmake)
if(NOT config_files OR NOT version_files)
  message(FATAL_ERROR "strataConfig.cmake / strataConfigVersion.cmake not installed under ${prefix}")
endif()
foreach(header strata/core/fem/elastic_model.hpp strata/core/mesh/tet_mesh.hpp)
  if(NOT EXISTS ${prefix}/include/${header})
    message(FATAL_ERROR "header ${header} not installed")
  endif()
endforeach()

# An installed program finds its libraries through its RUNPATH alone.
if(EXISTS ${prefix}/bin/strata)
  run("installed strata --help" ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH
      ${prefix}/bin/strata --help)
endif()

set(compiler_arg)
if(STRATA_CXX_COMPILER)
  set(compiler_arg -DCMAKE_CXX_COMPILER=${STRATA_CXX_COMPILER})
endif()
run("configure consumer" ${CMAKE_COMMAND} -S ${STRATA_CONSUMER_SOURCE_DIR} -B ${consumer_build}
    -DCMAKE_BUILD_TYPE=${STRATA_CONFIG} -DCMAKE_PREFIX_PATH=${prefix} ${compiler_arg})
run("build consumer" ${CMAKE_COMMAND} --build ${consumer_build} --config ${STRATA_CONFIG})

find_program(consumer strata_consumer PATHS ${consumer_build} ${consumer_build}/${STRATA_CONFIG}
             NO_DEFAULT_PATH REQUIRED)
run("run consumer" ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${consumer})
