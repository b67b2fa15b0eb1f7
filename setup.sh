#!/usr/bin/env bash
# fcm set-up and build driver for Debian 12 (run as root, or with sudo available).
#   bash setup.sh demo    install what is missing, build, run fcm-sim on its built-in default
#   bash setup.sh test    install what is missing, build, run the default test suite
#   bash setup.sh bench   build and run the benchmarks (ctest label "bench")
#   bash setup.sh deps    only install the Debian packages
# Environment: FCM_BUILD_DIR (default: build), FCM_CMAKE_ARGS (extra CMake arguments),
#              FCM_JOBS (parallel build jobs, default: number of cores).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${FCM_BUILD_DIR:-$here/build}
jobs=${FCM_JOBS:-$(nproc 2>/dev/null || echo 2)}
packages=(build-essential cmake pkg-config libopenblas-dev liblapacke-dev libglpk-dev
          libsuitesparse-dev libcjson-dev libgmsh-dev gnuplot-nox)

deps() {
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup.sh: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

configure_and_build() {
  # shellcheck disable=SC2086
  cmake -S "$here" -B "$build" ${FCM_CMAKE_ARGS:-} >/dev/null
  cmake --build "$build" -j "$jobs"
}

case "${1:-}" in
  deps) deps ;;
  demo)
    deps
    configure_and_build
    shift
    "$build/fcm-sim" "$@"
    ;;
  test)
    deps
    configure_and_build
    (cd "$build" && ctest --output-on-failure -j "$jobs" -LE 'bench|slow')
    ;;
  bench)
    deps
    configure_and_build
    (cd "$build" && ctest --output-on-failure -L bench)
    ;;
  *)
    sed -n '2,9p' "$0"
    exit 2
    ;;
esac
