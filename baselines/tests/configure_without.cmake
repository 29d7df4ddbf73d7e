# Configures the project with one competitor's library hidden and checks that
# the configure succeeds, says which rows it dropped, generates a table
# without them, and that the table and the facade compile. Compiling the
# whole project again would cost minutes; baselines/README.md ("Adding a
# baseline") gives the command for a full build without FCL.
# Run as: cmake -DSOURCE_DIR=... -DWORK_DIR=... -DHIDE=fcl|ccd|bullet -DCXX=... -P configure_without.cmake
cmake_minimum_required(VERSION 3.16)
file(REMOVE_RECURSE ${WORK_DIR})
# The package name find_package uses (Bullet's config file is BulletConfig-float64.cmake).
set(package ${HIDE})
if(HIDE STREQUAL "bullet")
  set(package Bullet)
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -G "Unix Makefiles"
                        -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX}
                        -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON -DIDCOL_BUILD_PYTHON=OFF
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring with ${HIDE} hidden failed (${rc})")
endif()
if(HIDE STREQUAL "fcl")
  set(expect_message "idcol: FCL not found: the FCL baselines")
  set(expect_table "competitors_ccd")
  set(absent_tables "competitors_fcl")
elseif(HIDE STREQUAL "bullet")
  set(expect_message "idcol: Bullet (double precision) not found: the Bullet baselines")
  set(expect_table "competitors_fcl")
  set(absent_tables "competitors_bullet")
else()
  # FCL finds libccd through the same config, so hiding libccd hides both
  # (DCOL, this project's C++, stays; so do Bullet's rows where Bullet is).
  set(expect_message "idcol: libccd not found: the libccd baselines")
  set(expect_table "competitors_dcol")
  set(absent_tables "competitors_fcl" "competitors_ccd")
endif()
string(FIND "${out}${err}" "${expect_message}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the configure output does not say \"${expect_message}\"")
endif()
file(READ ${WORK_DIR}/baselines/competitor_table.cpp table)
string(FIND "${table}" "${expect_table}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the generated table lacks \"${expect_table}\":\n${table}")
endif()
foreach(absent IN LISTS absent_tables)
  string(FIND "${table}" "${absent}(" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the generated table still has \"${absent}\":\n${table}")
  endif()
endforeach()
# The table, the registry and the facade compile without the hidden library
# (their object files only: the library's dependencies are not rebuilt).
execute_process(COMMAND ${CMAKE_MAKE_PROGRAM} -C ${WORK_DIR}/baselines competitor_table.o src/registry.o src/baselines.o
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "compiling the table without ${HIDE} failed (${rc}):\n${out}${err}")
endif()
