#!/usr/bin/env bash
# The Python module's install line (README, "Python"): installs the Debian packages it needs
# (scripts/deps.sh python; as root on a fresh Debian), builds `import simsr` for /usr/bin/python3
# in build-python/ (Release; no tests, examples or benchmarks) and installs it with the
# header-only library under CMAKE_INSTALL_PREFIX (default /usr/local: the package lands in
# /usr/local/lib/python3.X/dist-packages/simsr, on /usr/bin/python3's path). Then imports it from
# another folder, so a module that only loads from the build tree fails here.
#
#   bash scripts/install_python.sh                 build and install
#   SIMSR_PREFIX=/opt/simsr bash scripts/install_python.sh   another prefix (add its site-packages to PYTHONPATH)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/deps.sh python
build=${SIMSR_PYTHON_BUILD_DIR:-build-python}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="${SIMSR_PREFIX:-/usr/local}" -DSIMSR_WITH_PYTHON=ON \
  -DSIMSR_BUILD_TESTS=OFF -DSIMSR_BUILD_EXAMPLES=OFF -DSIMSR_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target simsr_python
cmake --install "$build" >/dev/null
dir=$(grep '^SIMSR_PYTHON_INSTALL_DIR:' "$build/CMakeCache.txt" | cut -d= -f2-)
cd /
PYTHONPATH="${SIMSR_PREFIX:+$dir}${PYTHONPATH:+:$PYTHONPATH}" /usr/bin/python3 -c \
  "import simsr; print('simsr', simsr.__version__, 'installed in', simsr.__path__[0]); print(simsr.method_names())"
