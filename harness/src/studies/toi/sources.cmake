# The time-of-impact study's sources in idcol_harness_lib (included by
# harness/CMakeLists.txt).
target_sources(idcol_harness_lib PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/toi.cpp
  ${CMAKE_CURRENT_LIST_DIR}/toi_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/toi_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/toi_kind.cpp)
# FCL's continuousCollide beside the time-of-impact study, where FCL was built.
if(TARGET idcol_baseline_fcl)
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/toi_baselines.cpp)
  target_link_libraries(idcol_harness_lib PRIVATE idcol_baseline_fcl)
else()
  target_sources(idcol_harness_lib PRIVATE ${CMAKE_CURRENT_LIST_DIR}/toi_none.cpp)
endif()
