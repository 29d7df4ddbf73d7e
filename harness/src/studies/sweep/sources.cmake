# The sweep's sources (harness/CMakeLists.txt: idcol_kind_sources). The
# agreement pass runs FCL, libccd and the exact oracles where the baselines
# were built; agreement_none.cpp is its twin without them.
idcol_kind_sources(sweep.cpp sweep_markdown.cpp sweep_metrics.cpp sweep_scene.cpp sweep_study.cpp agreement.cpp
                   NEEDS idcol_baselines WITH agreement_baselines.cpp ELSE agreement_none.cpp)
