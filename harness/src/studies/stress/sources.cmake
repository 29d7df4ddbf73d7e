# The stress suite's sources in idcol_harness_lib (included by harness/CMakeLists.txt).
target_sources(idcol_harness_lib PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/stress.cpp
  ${CMAKE_CURRENT_LIST_DIR}/random_bodies_stress.cpp
  ${CMAKE_CURRENT_LIST_DIR}/stress_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/stress_scene.cpp
  ${CMAKE_CURRENT_LIST_DIR}/stress_study.cpp)
