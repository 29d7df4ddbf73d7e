# The stress suite's sources (harness/CMakeLists.txt: idcol_kind_sources).
idcol_kind_sources(stress.cpp random_bodies_stress.cpp stress_metrics.cpp stress_scene.cpp stress_study.cpp)
