#!/usr/bin/env bash
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer
# (-DIDCOL_SANITIZE=ON, gcc by default) into ${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize}
# and runs the whole ctest suite there. -O1 keeps the run short; Debug keeps
# Eigen's bounds assertions. Benchmarks are not built (nothing runs them here).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${IDCOL_SANITIZE_BUILD_DIR:-build-sanitize}
cmake -S . -B "$BUILD_DIR" -DIDCOL_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DIDCOL_BUILD_BENCHMARKS=OFF "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
# Leaks are findings too; halt on the first error of any kind.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/scripts/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)"
