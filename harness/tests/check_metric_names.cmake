# Each declared metric is named by one key in the results files, and that
# key is spelled in one source file: its study's keys header (io/keys.hpp or
# studies/<kind>/<kind>_keys.hpp). The writer, the reader, the merge, the
# Markdown, the terminal summary and the metric table use the constant; the
# plot scripts read the names from `idcol_harness metrics --json`. This test
# takes the keys from `idcol_harness metrics --keys` and fails for a key
# found quoted ("key" or 'key') in more than one file, or in none, of
# harness/src and scripts/. Comments are not searched: they may name a key.
#   cmake -DHARNESS=<idcol_harness> -DSOURCE_DIR=<project root> -P check_metric_names.cmake
execute_process(COMMAND ${HARNESS} metrics --keys OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "idcol_harness metrics --keys failed (${rc}): ${err}")
endif()
string(STRIP "${out}" out)
string(REPLACE "\n" ";" keys "${out}")
list(LENGTH keys nkeys)
if(nkeys LESS 20)
  message(FATAL_ERROR "idcol_harness metrics --keys listed ${nkeys} keys; expected the keys of every study kind")
endif()

file(GLOB_RECURSE cpp_files ${SOURCE_DIR}/harness/src/*.cpp ${SOURCE_DIR}/harness/src/*.hpp)
file(GLOB_RECURSE script_files ${SOURCE_DIR}/scripts/*)
# record_test_figures.py reads GoogleTest's JSON report (its keys, such as
# "failures", are GoogleTest's), never a harness results file.
list(FILTER script_files EXCLUDE REGEX "/record_test_figures\\.py$")
set(texts "")
foreach(f IN LISTS cpp_files script_files)
  file(READ ${f} content)
  if(f MATCHES "\\.(cpp|hpp)$")
    string(REGEX REPLACE "//[^\n]*" "" content "${content}")
  else()
    # Whole-line comments, and trailing ones that hold no quote.
    string(REGEX REPLACE "(^|\n)[ \t]*#[^\n]*" "\\1" content "${content}")
    string(REGEX REPLACE "[ \t]#[^\n\"']*" "" content "${content}")
  endif()
  string(MD5 id "${f}")
  set(text_${id} "${content}")
  list(APPEND texts ${f})
endforeach()

set(problems "")
foreach(k IN LISTS keys)
  set(found "")
  foreach(f IN LISTS texts)
    string(MD5 id "${f}")
    string(FIND "${text_${id}}" "\"${k}\"" a)
    string(FIND "${text_${id}}" "'${k}'" b)
    if(a GREATER -1 OR b GREATER -1)
      file(RELATIVE_PATH rel ${SOURCE_DIR} ${f})
      list(APPEND found ${rel})
    endif()
  endforeach()
  list(LENGTH found n)
  if(NOT n EQUAL 1)
    list(JOIN found ", " where)
    list(APPEND problems "\"${k}\" is spelled in ${n} files (${where}): spell it once, as a key constant (io/keys.hpp)")
  endif()
endforeach()
if(problems)
  list(JOIN problems "\n  " text)
  message(FATAL_ERROR "metric keys spelled more than once:\n  ${text}")
endif()
list(LENGTH texts nfiles)
message(STATUS "metric names: each of ${nkeys} keys spelled in one of ${nfiles} files")
