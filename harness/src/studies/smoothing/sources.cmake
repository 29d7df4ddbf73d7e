# The smoothing study's sources (harness/CMakeLists.txt: idcol_kind_sources).
# Its kind, metrics and scene reader are in every build, so that its results
# files and scenes are read everywhere; the study itself needs the
# baselines' exact oracles, and smoothing_none.cpp, its twin, refuses a
# smoothing scene where they were not built.
idcol_kind_sources(smoothing_kind.cpp smoothing_metrics.cpp smoothing_scene.cpp
                   NEEDS idcol_baselines WITH smoothing_study.cpp smoothing.cpp ELSE smoothing_none.cpp)
