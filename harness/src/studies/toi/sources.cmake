# The time-of-impact study's sources (harness/CMakeLists.txt:
# idcol_kind_sources), with FCL's continuousCollide beside it where FCL was
# built (toi_none.cpp is the twin without it).
idcol_kind_sources(toi.cpp toi_metrics.cpp toi_scene.cpp toi_kind.cpp
                   NEEDS idcol_baseline_fcl WITH toi_baselines.cpp ELSE toi_none.cpp)
