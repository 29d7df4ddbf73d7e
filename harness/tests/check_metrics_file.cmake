# results/metrics.json, which the plot scripts read (scripts/harness_metrics.py),
# is what `idcol_harness metrics --json` prints now: a metric declared,
# renamed or moved shows up here until the file is written again with
#   idcol_harness metrics --json > results/metrics.json
#   cmake -DHARNESS=<idcol_harness> -DSOURCE_DIR=<project root> -P check_metrics_file.cmake
execute_process(COMMAND ${HARNESS} metrics --json OUTPUT_VARIABLE now ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "idcol_harness metrics --json failed (${rc}): ${err}")
endif()
file(READ ${SOURCE_DIR}/results/metrics.json checked_in)
if(NOT now STREQUAL checked_in)
  message(FATAL_ERROR "results/metrics.json differs from `idcol_harness metrics --json`; write it again with\n"
                      "  idcol_harness metrics --json > results/metrics.json")
endif()
message(STATUS "results/metrics.json matches the declared metrics")
