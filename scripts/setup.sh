#!/usr/bin/env bash
# Set up everything hilldem needs on a fresh Debian 12 machine, then configure and build it.
# Idempotent: packages already present are skipped, and the build is incremental.
#   scripts/setup.sh [build-dir]        (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"

# Debian packages and why each is here:
#   g++, cmake, make      the compiler and build system
#   libtomlplusplus-dev   TOML parser for scenario files (line/column in syntax errors)
#   libcli11-dev          command-line parsing (subcommands, typed options, --help)
#   libfmt-dev            number formatting for tables and CSV
#   libgtest-dev          GoogleTest, the test framework (run through CTest)
#   python3-vtk9          VTK's own XML reader, to prove in a test that snapshots open in ParaView/VTK
#   python3-matplotlib    the plots of histories (scripts/plot_history.py, docs/figures/)
#                         and the triaxial study's figures (scripts/plot_triaxial.py, memo Figs. 18, 20-22)
#   pybind11-dev, python3-dev
#                         the Python module `import hilldem` (python/): the binding library and
#                         the headers of Debian's /usr/bin/python3
#   python3-numpy         the module's arrays (numpy views of the balls, contacts, lab-test results)
#   python3-pytest        the module's tests (tests/python/, run by CTest)
#   clang, libclang-rt-14-dev, libomp-14-dev
#                         libFuzzer with AddressSanitizer/UBSan for the fuzz targets (fuzz/, run
#                         bounded by a test), and OpenMP for that clang build
#   libopenmpi-dev, openmpi-bin
#                         MPI for the domain decomposition over ranks (`mpirun -np N hilldem bench`,
#                         docs/mpi.md): the library and headers, and mpirun
#   libtrilinos-zoltan-dev
#                         Zoltan's recursive coordinate bisection: the ranks' sub-domains (docs/mpi.md)
packages=(g++ cmake make libtomlplusplus-dev libcli11-dev libfmt-dev libgtest-dev
          python3-vtk9 python3-matplotlib pybind11-dev python3-dev python3-numpy python3-pytest
          clang libclang-rt-14-dev libomp-14-dev libopenmpi-dev openmpi-bin libtrilinos-zoltan-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get install -y -q "${missing[@]}" >/dev/null 2>&1 || {
    $sudo_cmd apt-get update -q >/dev/null
    $sudo_cmd apt-get install -y -q "${missing[@]}"
  }
fi

# Profile-guided build (CMakeLists.txt, HILLDEM_PGO; HILLDEM_PGO=0 in the environment turns it off):
# an instrumented hilldem in $build_dir/pgo/instrumented, trained by scripts/pgo_train.sh whenever it
# was rebuilt (that is, whenever a source changed) or the training set changed, then the real build
# with its profiles.
# (GCC only: with another compiler, as CXX=clang++, the build is a plain one.)
pgo_args=(-DHILLDEM_PGO= -DHILLDEM_PGO_DIR=)
use_pgo="${HILLDEM_PGO:-1}"
if [ "$use_pgo" != 0 ] && ! "${CXX:-c++}" -v 2>&1 | grep -q '^gcc version'; then
  echo "setup: ${CXX:-c++} is not GCC: building without profile guidance"
  use_pgo=0
fi
if [ "$use_pgo" != 0 ]; then
  mkdir -p "$build_dir/pgo"
  pgo_root=$(cd "$build_dir/pgo" && pwd)
  profile="$pgo_root/profile"
  cmake -S . -B "$pgo_root/instrumented" -DCMAKE_BUILD_TYPE=Release -DHILLDEM_ENABLE_TESTS=OFF \
    -DHILLDEM_PGO=generate -DHILLDEM_PGO_DIR="$profile" >/dev/null
  cmake --build "$pgo_root/instrumented" --target hilldem -j"$(nproc)"
  if [ ! -f "$profile/stamp" ] || [ "$pgo_root/instrumented/hilldem" -nt "$profile/stamp" ] ||
     [ scripts/pgo_train.sh -nt "$profile/stamp" ]; then
    echo "setup: training the profile-guided build (scripts/pgo_train.sh)"
    rm -rf "$profile"
    mkdir -p "$profile"
    scripts/pgo_train.sh "$pgo_root/instrumented/hilldem"
    touch "$profile/stamp"
  fi
  pgo_args=(-DHILLDEM_PGO=use -DHILLDEM_PGO_DIR="$profile")
fi

# The MPI domain decomposition (CMakeLists.txt, HILLDEM_MPI) once OpenMPI and Zoltan are here.
mpi_args=(-DHILLDEM_MPI=OFF)
if command -v mpirun >/dev/null && [ -f /usr/include/trilinos/zoltan.h ]; then mpi_args=(-DHILLDEM_MPI=ON); fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "${pgo_args[@]}" "${mpi_args[@]}" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"

# `import hilldem` for Debian's /usr/bin/python3: a hilldem.pth file in its site-packages naming the
# build's module folder (<build-dir>/python), rewritten on every run (idempotent; the last build set
# up is the one imported). Remove the file to undo it.
py_site=$(/usr/bin/python3 -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
py_dir=$(cd "$build_dir/python" && pwd)
sudo_cmd=""
[ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
$sudo_cmd mkdir -p "$py_site"
echo "$py_dir" | $sudo_cmd tee "$py_site/hilldem.pth" >/dev/null
/usr/bin/python3 -c "import hilldem" || { echo "setup: /usr/bin/python3 cannot import hilldem from $py_dir" >&2; exit 1; }
echo "setup: /usr/bin/python3 imports hilldem from $py_dir ($py_site/hilldem.pth)"
