#!/usr/bin/env bash
# fcm set-up and build driver for Debian 12 (run as root, or with sudo available).
#   bash setup.sh demo    install what is missing, build, run fcm-sim on its built-in default
#   bash setup.sh test    install what is missing, build, run the default test suite
#   bash setup.sh bench   build and run the benchmarks (ctest label "bench")
#   bash setup.sh deps    only install the Debian packages
#   bash setup.sh install [PREFIX]
#                         install what is missing, build, install the library, programs and
#                         the Python package fcm into PREFIX (default /usr/local, where
#                         Debian's python3 finds the package)
#   bash setup.sh deps --petsc
#                         also the optional PETSc + MPI backend's (petsc-dev, openmpi-bin;
#                         `test --petsc` etc. likewise): the build then has the backend
#                         (CMake option FCM_WITH_PETSC=ON; without --petsc it is off) and the
#                         default test run includes the mpi-labelled tests
#   bash setup.sh install-check
#                         build, install into a temporary prefix, move it, and build and run
#                         the example host programs (apps/examples) against the installed
#                         package with `pkg-config --cflags --libs fcm` and find_package(fcm)
#                         (with the PETSc component, host_petsc with fcm-petsc and fcm::petsc),
#                         and import the Python package fcm from the moved tree
# Environment: FCM_BUILD_DIR (default: build), FCM_CMAKE_ARGS (extra CMake arguments),
#              FCM_JOBS (parallel build jobs, default: number of cores).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${FCM_BUILD_DIR:-$here/build}
jobs=${FCM_JOBS:-$(nproc 2>/dev/null || echo 2)}
packages=(build-essential cmake pkg-config libopenblas-dev liblapacke-dev libglpk-dev
          libsuitesparse-dev libcjson-dev libgmsh-dev gnuplot-nox
          python3-dev python3-numpy python3-pytest python3-matplotlib)
# --petsc (the argument after the command): the PETSc + MPI backend's packages too
if [ "${2:-}" = "--petsc" ]; then
  packages+=(petsc-dev openmpi-bin)
  FCM_CMAKE_ARGS="-DFCM_WITH_PETSC=ON ${FCM_CMAKE_ARGS:-}"
  set -- "$1" "${@:3}"
fi

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

# Configure and build; with arguments, only those targets (and what they need).
configure_and_build() {
  local targets=()
  [ $# -gt 0 ] && targets=(--target "$@")
  # shellcheck disable=SC2086
  cmake -S "$here" -B "$build" ${FCM_CMAKE_ARGS:-} >/dev/null
  cmake --build "$build" -j "$jobs" "${targets[@]}"
}

# Install the build into a temporary prefix, move the tree (nothing may hard-code the build
# machine or the install location), then build the example host programs installed with it
# (share/doc/fcm/examples) against it both ways
# and run them: the C one with `cc ... $(pkg-config --cflags --libs fcm)` (no --static, no
# other flag), both with find_package(fcm) from apps/examples/CMakeLists.txt. FCM_KEEP_PREFIX=1
# keeps the prefix (printed) for a look.
install_check() {
  local prefix pkgdir pcdir src ex
  prefix=$(mktemp -d)
  [ "${FCM_KEEP_PREFIX:-0}" = 1 ] || trap "rm -rf '$prefix'" RETURN
  cmake --install "$build" --prefix "$prefix/staging" >/dev/null
  mv "$prefix/staging" "$prefix/fcm"
  pkgdir=$(dirname "$(find "$prefix/fcm" -name fcmConfig.cmake)")
  if grep -nE '(^|[";( :])/[A-Za-z]|staging' "$pkgdir"/fcm*Targets*.cmake; then
    echo "install check: the exported targets hard-code paths (above)" >&2
    return 1
  fi
  # a shared libfcm exports the public API (fcm_*) and, for its PETSc component, the internal
  # functions declared FCM_COMPONENT_API in lib/src (no other fcm__ name, no symbol of another
  # name: OpenMP's named critical sections and the linker's section markers __bss_start, _edata,
  # _end aside); it needs no MPI or PETSc library, whatever the build
  local so bad component
  so=$(find "$prefix/fcm" -name 'libfcm.so.*' -type f | head -n 1)
  if [ -n "$so" ]; then
    component=$(grep -rhoE '^FCM_COMPONENT_API [^(]*\bfcm__[a-z0-9_]+\(' "$here/lib/src" |
                grep -oE 'fcm__[a-z0-9_]+\($' | tr -d '(' | sort -u)
    bad=$(nm -D --defined-only "$so" | awk '{print $3}' |
          grep -vE '^(fcm_[A-Za-z0-9]|\.gomp_critical_user_|__bss_start$|_edata$|_end$)' |
          grep -vxF -f <(echo "$component") || true)
    if [ -n "$bad" ]; then
      echo "install check: libfcm exports symbols outside the public API:" >&2
      echo "$bad" | head -n 20 >&2
      return 1
    fi
    if readelf -d "$so" | grep -E 'NEEDED.*(mpi|petsc)'; then
      echo "install check: libfcm needs an MPI or PETSc library (above)" >&2
      return 1
    fi
  fi
  pcdir=$(dirname "$(find "$prefix/fcm" -name fcm.pc)")
  src=$(dirname "$(find "$prefix/fcm" -path '*/examples/host_static.c')")
  [ -f "$src/host_dynamic.cpp" ] && [ -f "$src/CMakeLists.txt" ]
  ex="$prefix/examples"
  mkdir -p "$ex/out-pc" "$ex/out-cmake"
  # pkg-config, as a user would type it; the serial package names no MPI, built with or
  # without the PETSc component (its own fcm-petsc.pc carries MPI and PETSc)
  local pcline
  pcline="$(PKG_CONFIG_PATH="$pcdir" pkg-config --cflags --libs fcm) \
$(PKG_CONFIG_PATH="$pcdir" pkg-config --static --libs fcm)"
  if echo "$pcline" | grep -iE 'mpi|petsc'; then
    echo "install check: pkg-config fcm names MPI or PETSc (above)" >&2
    return 1
  fi
  # shellcheck disable=SC2046
  cc -std=c11 "$src/host_static.c" -o "$ex/host_static-pc" \
    $(PKG_CONFIG_PATH="$pcdir" pkg-config --cflags --libs fcm)
  # shellcheck disable=SC2046
  c++ -std=c++11 "$src/host_dynamic.cpp" -o "$ex/host_dynamic-pc" \
    $(PKG_CONFIG_PATH="$pcdir" pkg-config --cflags --libs fcm)
  "$ex/host_static-pc" "$ex/out-pc" >/dev/null
  [ -s "$ex/out-pc/host_static_surface.vtu" ] && [ -s "$ex/out-pc/host_static_background.vtu" ]
  # the package says whether fcm has the PETSc component (pkg-config variable petsc,
  # FCM_HAVE_PETSC of fcmConfig.cmake and fcm/version.h); with it, host_petsc builds with
  # `pkg-config --cflags --libs fcm-petsc` and runs (alone: MPI's singleton start), and without
  # it neither its headers nor its .pc file are installed
  local have
  have=$(PKG_CONFIG_PATH="$pcdir" pkg-config --variable=petsc fcm)
  grep -q "FCM_HAVE_PETSC $have" "$prefix/fcm/include/fcm/version.h"
  if [ "$have" = 1 ]; then
    grep -q "set(FCM_HAVE_PETSC ON)" "$pkgdir/fcmConfig.cmake"
    [ -f "$prefix/fcm/include/fcm/petsc.h" ] && [ -f "$prefix/fcm/include/fcm/scene_petsc.h" ]
    # shellcheck disable=SC2046
    cc -std=c11 "$src/host_petsc.c" -o "$ex/host_petsc-pc" \
      $(PKG_CONFIG_PATH="$pcdir" pkg-config --cflags --libs fcm-petsc) -lm
    "$ex/host_petsc-pc" >/dev/null
  else
    [ ! -e "$prefix/fcm/include/fcm/petsc.h" ] && [ ! -e "$pcdir/fcm-petsc.pc" ]
  fi
  # the serial host programs need no MPI library at run time either
  if readelf -d "$ex/host_static-pc" "$ex/host_dynamic-pc" | grep -E 'NEEDED.*(mpi|petsc)'; then
    echo "install check: a serial host program needs MPI or PETSc (above)" >&2
    return 1
  fi
  # CMake, find_package(fcm)
  cmake -S "$src" -B "$ex/build" -DCMAKE_PREFIX_PATH="$prefix/fcm" >/dev/null
  cmake --build "$ex/build" >/dev/null
  "$ex/build/host_static" "$ex/out-cmake" >/dev/null
  "$ex/build/host_dynamic" "$ex/out-cmake" >/dev/null
  [ -s "$ex/out-cmake/host_dynamic_surface.vtu" ]
  if readelf -d "$ex/build/host_static" "$ex/build/host_dynamic" | grep -E 'NEEDED.*(mpi|petsc)'; then
    echo "install check: a serial host program (find_package) needs MPI or PETSc (above)" >&2
    return 1
  fi
  if [ "$have" = 1 ]; then # find_package(fcm OPTIONAL_COMPONENTS petsc) built host_petsc
    "$ex/build/host_petsc" >/dev/null
  else
    [ ! -e "$ex/build/host_petsc" ]
  fi
  # the Python package (when built) imports from the moved tree: its module finds the moved
  # libfcm through its $ORIGIN rpath
  local pyinit python
  pyinit=$(find "$prefix/fcm" -path '*/fcm/__init__.py' | head -n 1)
  local pymsg=""
  if [ -n "$pyinit" ]; then
    python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$build/CMakeCache.txt")
    PYTHONPATH=$(dirname "$(dirname "$pyinit")") "${python:-python3}" -c \
      "import fcm; ctx = fcm.Context(); assert fcm.__version__ and fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [1, 1, 1]).num_cells == 1"
    pymsg="; the Python package imported from the moved tree"
  fi
  # the installed programs find the moved libfcm through their $ORIGIN rpath
  if [ -x "$prefix/fcm/bin/fcm-sim" ]; then "$prefix/fcm/bin/fcm-sim" --help >/dev/null; fi
  echo "install check: examples built against the installed package (pkg-config and"\
       "find_package) and run: host_static, host_dynamic$([ "$have" = 1 ] && echo ", host_petsc")$pymsg"
  [ "${FCM_KEEP_PREFIX:-0}" = 1 ] && echo "install check: prefix kept: $prefix"
  return 0
}

case "${1:-}" in
  deps) deps ;;
  demo)
    deps
    echo "setup.sh: building the library and fcm-sim (a few minutes the first time)"
    configure_and_build fcm-sim >/dev/null # the library and the program, not the tests
    shift
    "$build/fcm-sim" "$@"
    ;;
  test)
    deps
    configure_and_build
    (cd "$build" && ctest --output-on-failure -j "$jobs" -LE 'bench|slow')
    ;;
  install)
    deps
    configure_and_build
    cmake --install "$build" --prefix "${2:-/usr/local}" >/dev/null
    echo "setup.sh: installed into ${2:-/usr/local}"
    ;;
  install-check)
    deps
    configure_and_build
    install_check
    ;;
  bench)
    deps
    configure_and_build
    (cd "$build" && ctest --output-on-failure -L bench)
    ;;
  *)
    sed -n '2,23p' "$0"
    exit 2
    ;;
esac
