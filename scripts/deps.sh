#!/usr/bin/env bash
# Installs the Debian packages simsr needs for a given job, only those missing.
#   scripts/deps.sh python the Python module alone (scripts/install_python.sh): the library's packages,
#                          a compiler, cmake and ninja, pybind11-dev, python3-dev and NumPy
#   scripts/deps.sh run    build + run the main job (tetgen for the face's HR mesh; python3-vtk9 with
#                          xvfb for the renders of scripts/render_comparison.py; npm, with which the
#                          build vendors three.js for the report page)
#   scripts/deps.sh test   + test peers (meshio, scipy, torch, gmsh, tetgen; python3-vtk9 with xvfb for
#                          scripts/render_face.py; chromium for the report page) and what scripts/test.sh's
#                          clang builds need: clang, libclang-rt-dev (ASan, UBSan, TSan, libFuzzer),
#                          libomp-dev (LLVM's OpenMP and its Archer tool, libarcher.so, for TSan) and
#                          llvm (llvm-symbolizer: sanitizer reports with file and line); libsuitesparse-dev
#                          (CHOLMOD, the optional physics::CholmodCholesky, whose tests run there) with
#                          libopenblas0-pthread (the BLAS CHOLMOD's supernodal factorization calls:
#                          with Debian's reference BLAS a Newton step of the 4,225-vertex cloth took
#                          0.65 s, with OpenBLAS 0.21 s) and
#                          libcgal-dev (CGAL, the optional isotropic_remesh and remeshed SoftDECA template);
#                          pybind11-dev and python3-dev (the optional Python module, -DSIMSR_WITH_PYTHON=ON) and
#                          python3-pytest (its suite); python3-matplotlib for the module's face example
#                          (examples/python/face_frame.py), which the test run runs; libopenmpi-dev and
#                          openmpi-bin (mpirun) for the optional simsr::mpi, -DSIMSR_WITH_MPI=ON, whose
#                          suite runs on 2 ranks
# Needs root (or sudo) only when something is missing.
set -euo pipefail
job=${1:-test}

if [[ $job == python ]]; then
  pkgs=(build-essential cmake ninja-build libeigen3-dev libxtensor-dev libnanoflann-dev libzip-dev nlohmann-json3-dev
        python3 python3-numpy pybind11-dev python3-dev)
else
  pkgs=(build-essential cmake ninja-build
        libeigen3-dev libxtensor-dev libnanoflann-dev libzip-dev
        doctest-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
        python3 python3-numpy tetgen python3-vtk9 xvfb xauth)
  # npm: Debian's package where no npm command exists yet. A nodejs from another repository ships
  # its own npm and conflicts with Debian's (apt then refuses: "nodejs : Conflicts: npm").
  command -v npm >/dev/null || pkgs+=(npm)
fi
if [[ $job == test ]]; then
  pkgs+=(python3-meshio python3-scipy python3-torch gmsh clang libclang-rt-dev libomp-dev llvm chromium libsuitesparse-dev libopenblas0-pthread libcgal-dev
         pybind11-dev python3-dev python3-pytest python3-matplotlib libopenmpi-dev openmpi-bin)
fi

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
((${#missing[@]} == 0)) && exit 0

echo "simsr: installing missing Debian packages: ${missing[*]}" >&2
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "simsr: need root to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
