# Shared by scripts/demo and scripts/test: install what is missing, configure, build.
# Sourced, not run. Every dependency is a Debian package (README.md, "Dependencies").
set -euo pipefail

GYROCAL_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# ensure_packages PKG...: install the Debian packages that are missing (as root), or print the exact
# install line and stop (as anyone else).
ensure_packages() {
  local missing=()
  local pkg
  for pkg in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  if [ "$(id -u)" -eq 0 ]; then
    echo "gyrocal: installing ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2
    apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
  else
    echo "gyrocal: missing Debian packages. Install them with:" >&2
    echo "  sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
}

# libjs-chart.js is inlined into the HTML report; chromium runs the report's browser test (docs/report.md).
# What the build needs (libjs-chart.js: the plotting library the HTML report inlines; pybind11-dev, python3-dev and
# python3-numpy: the Python module, built for Debian's /usr/bin/python3, docs/python.md; libsqlite3-dev: the
# calibration history's database, embedded; libssl-dev: OpenSSL's libcrypto for the records' SHA-256, docs/history.md).
GYROCAL_BUILD_PACKAGES=(g++ cmake make libeigen3-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
                        libfmt-dev libfast-float-dev libgtest-dev libbenchmark-dev libjs-chart.js
                        pybind11-dev python3-dev python3-numpy libsqlite3-dev libssl-dev)
# What the tests need beyond the build: a headless browser that opens the report; pytest for the Python module.
GYROCAL_TEST_PACKAGES=(chromium python3-pytest)

# build_gyrocal DIR [CMAKE ARGS...]: configure and build into DIR (Release unless told otherwise).
build_gyrocal() {
  local dir=$1
  shift
  # ccache, when the machine has it (it is not required): a clone in another directory (CI's lone clone, a
  # second checkout) reuses the objects of an identical compile. Paths are hashed relative to the clone, so a
  # cached object is one the same source and flags gave; nothing is skipped, only recompiled less.
  local launcher=()
  if command -v ccache >/dev/null 2>&1; then
    export CCACHE_BASEDIR="$GYROCAL_ROOT" CCACHE_NOHASHDIR=true
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  fi
  cmake -S "$GYROCAL_ROOT" -B "$dir" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "$@" >&2
  cmake --build "$dir" -j "$(nproc)" >&2
}
