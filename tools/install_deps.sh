#!/usr/bin/env bash
# Installs everything Orrery needs to build, test and run on Debian 12 (as root, or with sudo).
# Idempotent and non-interactive: packages already present are left alone.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config
  libeigen3-dev libspectra-dev libfcl-dev libassimp-dev libsundials-dev libhdf5-dev hdf5-tools
  libsuitesparse-dev libyaml-cpp-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  calculix-ccx
  # FFT for tools/signal (KissFFT, BSD; FFTW's GPL does not fit the project's licence)
  libkissfft-dev
  # Plots of `orrery spectrum | compare | octave --png` (tools/plot/*.py, Debian's python3)
  python3 python3-numpy python3-matplotlib python3-h5py
  # gmsh (a separate program, GPL, never linked): STEP/IGES solids and tetrahedral meshing of
  # imported parts (import/gmsh_mesher.h); its OpenCASCADE reads the CAD files.
  gmsh
  # clang 14 with libFuzzer: the fuzz harnesses of the file readers (tools/fuzz/).
  clang-14 libfuzzer-14-dev
  # `mpirun -n N orrery study ...`: Open MPI (the study's MPI plugin links it; the orrery program
  # itself runs without it)
  libopenmpi-dev openmpi-bin
  # Optimized single-threaded BLAS/LAPACK: Debian's alternatives then point libblas.so.3 at it,
  # which CHOLMOD's supernodal factorization and the Lanczos solves use (a 100k-DOF gear
  # reduction: 49 s instead of 72 s on this project's 2-core machine).
  libopenblas0-serial
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
echo "install_deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install_deps: done"
