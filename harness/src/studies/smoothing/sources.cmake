# The smoothing study's sources in idcol_harness_lib (included by
# harness/CMakeLists.txt). Its kind, metrics and scene reader are in every
# build, so that its results files and scenes are read everywhere; the study
# itself needs the baselines' exact oracles, and smoothing_none.cpp, its
# twin, refuses a smoothing scene where they were not built.
target_sources(idcol_harness_lib PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/smoothing_kind.cpp
  ${CMAKE_CURRENT_LIST_DIR}/smoothing_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/smoothing_scene.cpp)
if(TARGET idcol_baselines)
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/smoothing_study.cpp ${CMAKE_CURRENT_LIST_DIR}/smoothing.cpp)
else()
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/smoothing_none.cpp)
endif()
