# Installs the build tree into a scratch prefix, then configures, builds and
# runs a consumer project that finds the library with find_package(idcol),
# compiled by CXX (a compiler path). The consumer sets no C++ standard, so a
# compiler that defaults to C++14 (clang++-14) fails unless the exported
# idcol::core carries cxx_std_17.
# Run as: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DCXX=... -P check_install.cmake
# CXX empty: prints "SKIP: ..." (the test's SKIP_REGULAR_EXPRESSION) and stops.
if(NOT CXX)
  message("SKIP: no such compiler on this machine (${CXX_NAME}); scripts/setup.sh installs it")
  return()
endif()
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix --component Unspecified
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
# A build with the harness installs it too, so that the README's commands
# work with idcol_harness on the PATH.
if(EXISTS ${BUILD_DIR}/harness/idcol_harness)
  execute_process(COMMAND ${WORK_DIR}/prefix/bin/idcol_harness --version RESULT_VARIABLE rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cmake --install did not install a working bin/idcol_harness (--version: ${rc})")
  endif()
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/core/tests/install/consumer -B ${WORK_DIR}/build
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
                        -DCMAKE_CXX_COMPILER=${CXX}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring the consumer with find_package(idcol) and ${CXX} failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building the consumer with ${CXX} failed: ${rc}")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer's solve failed (built with ${CXX}): ${rc}")
endif()
