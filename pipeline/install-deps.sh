#!/bin/sh
# Check that Debian's packages this project needs are installed; install the missing
# ones with apt-get when running as root, otherwise print the exact command and fail.
# Arguments name further packages a target needs (make bench: openmpi-bin). lammps (Debian's lmp,
# with PERI) is for tests/e2e/test_lammps.py, the side-by-side run of docs/lammps.md: 72 MB with its
# libraries (apt-get install -s --no-install-recommends lammps: 5 packages).
# libopenblas0-serial: CHOLMOD's supernodal factorisation and solves run on BLAS; Debian's reference
# BLAS made them 4-5x slower (pd_linear_solvers 24 10 12, 1 thread: factorisation 2.79 s reference,
# 0.54 s OpenBLAS; solve 30 ms against 7 ms). The serial build keeps results the same for any
# OMP_NUM_THREADS; installing it makes it the system's libblas.so.3 (update-alternatives, auto).
# liblapack-dev: the dense LU of the Woodbury correction that takes broken bonds out of a factorised
# tangent (solver/src/linalg/woodbury.cpp; libarmadillo-dev pulls it in too).
# libhypre-dev: BoomerAMG, the algebraic multigrid preconditioner of quasi_static's CG on large 3D
# models (solver/src/linalg/amg.hpp).
# bubblewrap: the sandbox every gmsh that reads a case's .geo runs in (preprocess/sandbox.py);
# as root it needs nothing more, otherwise unprivileged user namespaces (docs/reliability.md).
set -eu
PACKAGES="$* g++ make cmake libgtest-dev libbenchmark-dev libarmadillo-dev libsuitesparse-dev liblapack-dev libhypre-dev libopenblas0-serial nlohmann-json3-dev zlib1g-dev \
libopenmpi-dev openmpi-bin \
gmsh python3-gmsh bubblewrap python3-meshio python3-numpy python3-scipy python3-yaml python3-matplotlib \
python3-pytest xvfb clang libclang-rt-14-dev libomp-14-dev lammps"
missing=""
for p in $PACKAGES; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -z "$missing" ]; then
    exit 0
fi
echo "missing Debian packages:$missing" >&2
if [ "$(id -u)" = 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -o DPkg::Lock::Timeout=600
    apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=600 $missing
else
    echo "run as root:  apt-get update && apt-get install -y$missing" >&2
    exit 1
fi
