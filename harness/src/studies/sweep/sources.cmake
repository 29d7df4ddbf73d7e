# The sweep's sources in idcol_harness_lib (included by harness/CMakeLists.txt).
target_sources(idcol_harness_lib PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/sweep.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweep_markdown.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweep_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweep_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sweep_study.cpp
  ${CMAKE_CURRENT_LIST_DIR}/agreement.cpp)
# The agreement pass with FCL, libccd and the exact oracles, where the
# baselines were built; agreement_none.cpp is its twin without them.
if(TARGET idcol_baselines)
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/agreement_baselines.cpp)
else()
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/agreement_none.cpp)
endif()
