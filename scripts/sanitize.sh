#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer (-DIDCOL_SANITIZE=ON:
# address, undefined and float-cast-overflow, -fno-sanitize-recover, Debug at
# -O1 so that Eigen's bounds assertions stay on) and runs ctest there.
#
#   scripts/sanitize.sh        # everything (gcc), the whole ctest suite, into
#                              # ${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize}
#   scripts/sanitize.sh --ci   # the CI stage (.ci/run): clang-14, the core and
#                              # harness tests only, into build-sanitize-ci;
#                              # IDCOL_SANITIZE_BUILD_ONLY=1 builds and stops
#
# The --ci subset covers every public entry point: the shapes, the solver and
# its options (idcol_core_tests: Shapes, Solver, Kkt, Lu6, BadInput), the
# derivatives (Derivatives), the contact-physics layer (idcol_physics_tests:
# broad phase, scene, the batch's per-row modes, integrator, rigid bodies),
# the scene reader, the runner, merge, compare, the
# stress suite and the command line (idcol_harness_tests, which run the
# idcol_harness executable), and the drivers' count parser
# (idcol_check_derivatives refusing a bad count). It leaves out the FCL/libccd/GLPK adapters
# (third-party code, and the costliest to build), the allocation-counting test
# (it replaces operator new, as ASan does), the fuzz corpus replay (the fuzz
# stage replays it under ASan + UBSan), the scale-out tests (shell, no new
# code paths) and idcol_toi_tests (four of its count and precision
# thresholds are tuned to GCC's rounding and fail under clang 14 -O1, with
# no sanitizer finding). clang because gcc spends minutes of CPU on single files of this
# code under ASan (core/README.md, "Sanitizers and fuzzing"); -gline-tables-only keeps
# file:line in reports for less build time. The same build holds the two
# libFuzzer targets (-DIDCOL_BUILD_FUZZERS=ON, every file instrumented for
# coverage by -fsanitize=fuzzer-no-link), so that the fuzz stage
# (scripts/ci_fuzz.sh) runs them without compiling the library again.
# Benchmarks are never built here.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${1:-}" == "--ci" ]]; then
  shift
  scripts/setup.sh fuzz  # clang-14 and its sanitizer runtimes
  BUILD_DIR=${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize-ci}
  CXX_COMPILER=${IDCOL_SANITIZE_CXX:-$(command -v clang++-14 || command -v clang++)}
  cmake -S . -B "$BUILD_DIR" -DIDCOL_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER="$CXX_COMPILER" \
    -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined" -DCMAKE_CXX_FLAGS_DEBUG="-O1 -gline-tables-only" \
    -DIDCOL_BUILD_FUZZERS=ON -DIDCOL_BUILD_BENCHMARKS=OFF -DIDCOL_BUILD_BASELINES=OFF -DIDCOL_BUILD_PYTHON=OFF "$@" >/dev/null
  cmake --build "$BUILD_DIR" -j"$(nproc)" --target idcol_core_tests idcol_physics_tests idcol_harness_tests idcol_harness idcol_check_random_bodies \
    idcol_check_derivatives fuzz_solve fuzz_scene
  [[ -n ${IDCOL_SANITIZE_BUILD_ONLY:-} ]] && exit 0
  # Only these executables are built: ctest runs their tests and leaves out
  # the plain add_test ones and the placeholders gtest_discover_tests leaves
  # for executables not built (<target>_NOT_BUILT); the docs tests run in the
  # test stage (they build and run the README in the plain build).
  CTEST_ARGS=(-E '^(scaleout\.|python\.|install_and_find_package\.|docs\.)|_NOT_BUILT$')
else
  BUILD_DIR=${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize}
  cmake -S . -B "$BUILD_DIR" -DIDCOL_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
    -DIDCOL_BUILD_BENCHMARKS=OFF "$@" >/dev/null
  cmake --build "$BUILD_DIR" -j"$(nproc)"
  CTEST_ARGS=()
fi
# Leaks are findings too; halt on the first error of any kind.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" "${CTEST_ARGS[@]}"
