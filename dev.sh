#!/usr/bin/env bash
# dev.sh -- install what is missing, build, and run SILC's main job or its tests.
#
#   ./dev.sh example   the 2-D diffusion example, embedded (writes diffusion2d.pgm)
#   ./dev.sh test      the whole test suite (ctest)
#   ./dev.sh build     just install and build
#
# Missing Debian packages are installed with apt-get (as root, or through sudo).
# SILC_BUILD_DIR (default build) and SILC_CMAKE_FLAGS select the build; under CI
# (CI=true) warnings are errors.
set -euo pipefail
cd "$(dirname "$0")"

# Why each package is here: see README.md, "Dependencies".
PACKAGES=(cmake make gcc gfortran pkg-config libinih-dev libreadline-dev
          libopenblas-dev liblapacke-dev libsuitesparse-dev libmumps-seq-dev libmumps-dev
          petsc-dev openmpi-bin libopenmpi-dev python3-numpy python3-scipy clang libpng-dev
          default-jdk-headless libhdf5-dev python3-h5py iproute2
          openssh-server openssh-client)

install_missing() {
    local missing=()
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    echo "dev.sh: installing ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
    local dir="${SILC_BUILD_DIR:-build}" flags=(${SILC_CMAKE_FLAGS:-})
    [ "${CI:-}" = "true" ] && flags+=(-DSILC_WERROR=ON)
    cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${flags[@]}" >/dev/null
    cmake --build "$dir" -j "$(nproc)"
}

# Tests pin thread counts so OpenBLAS and OpenMP do not fight over 2 cores.
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1} OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
# mpirun as root (CI runs as root) and more ranks than cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1

case "${1:-}" in
    example)
        install_missing; build
        "${SILC_BUILD_DIR:-build}/examples/diffusion2d" "${@:2}" ;;
    test)
        install_missing; build
        ctest --test-dir "${SILC_BUILD_DIR:-build}" --output-on-failure -j 2 ;;
    build)
        install_missing; build ;;
    *)
        echo "usage: ./dev.sh example|test|build" >&2; exit 2 ;;
esac
