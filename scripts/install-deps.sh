#!/usr/bin/env bash
# Installs every build, test and runtime dependency of scanbench from Debian 12
# packages. Idempotent and non-interactive: packages already present are skipped,
# so a second run costs a few dpkg queries and no network.
set -euo pipefail
# Options (any number, any order):
#   --bench   also PCL, the peer the benches measure against (a Release build
#             with SCANBENCH_BENCH on: scripts/build.sh passes it). PCL and what
#             it pulls in (VTK, Boost, MPI, a JDK) are half of a fresh machine's
#             download, so a build without the benches never installs it.
#   --tests   also what only the tests use (CloudCompare, a real reader of our
#             exports).

packages=(
  build-essential cmake ninja-build pkg-config ccache git
  libeigen3-dev libopencv-dev libpng-dev libtiff-dev zlib1g-dev libceres-dev libtbb-dev
  libsqlite3-dev libzstd-dev nlohmann-json3-dev libcli11-dev libpugixml-dev libnanoflann-dev
  libfmt-dev libgtest-dev libgmock-dev
  libimgui-dev libglfw3-dev libepoxy-dev libegl-dev libegl1-mesa-dev
  libgl1-mesa-dri xvfb xauth clang libclang-rt-14-dev
)

for option in "$@"; do
  case $option in
    --bench) packages+=(libpcl-dev) ;;
    --tests) packages+=(cloudcompare) ;;
    *) echo "usage: scripts/install-deps.sh [--bench] [--tests]" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
