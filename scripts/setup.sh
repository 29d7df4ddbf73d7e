#!/usr/bin/env bash
# Installs the Debian packages the project builds with. Idempotent: packages
# already present are not touched, and apt-get runs only if one is missing.
#   scripts/setup.sh          # build, tests, harness, baselines, plots, Python module, scale-out tests
#   scripts/setup.sh fuzz     # the same, plus clang and libFuzzer (scripts/fuzz*.sh)
set -euo pipefail
PACKAGES=(
  build-essential cmake ccache  # ccache: rebuilds of unchanged sources are cache hits
  clang                        # the find_package consumer test also builds with clang++ (C++14 by default)
  libeigen3-dev libfmt-dev libgtest-dev libbenchmark-dev
  libccd-dev libfcl-dev        # baselines
  libbullet-dev                # the Bullet baselines (its double-precision build, the -float64 libraries)
  libglpk-dev                  # exact LP oracle for polytopes
  libtomlplusplus-dev          # scene files
  nlohmann-json3-dev           # results files
  python3-matplotlib           # plots (scripts/plot_*.py, run with /usr/bin/python3)
  pybind11-dev python3-dev     # the Python module (core/python)
  python3-numpy python3-scipy python3-pytest  # its tests and the planning example
  python3-venv python3-pip python3-setuptools python3-wheel  # pip install . (setup.py drives CMake)
  python3-build                # python3 -m build --wheel --no-isolation
  python3-mypy                 # the type stubs' check (core/python/tests/test_stubs.py)
  parallel                     # the README's GNU parallel sharding recipe, run by its test
  slurmctld slurmd slurm-client munge  # a single-node Slurm cluster for the scale-out test (scripts/slurm/)
  chromium                     # headless browser: the history page's test (harness/tests/history_page.py)
  valgrind                     # instruction counts (scripts/callgrind_*.sh)
)
if [[ "${1:-}" == "fuzz" ]]; then
  PACKAGES+=(clang-14 libclang-rt-14-dev)  # libFuzzer and the sanitizer runtimes for clang
fi
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
