#!/usr/bin/env bash
# Installs every Debian (bookworm) package trajroi builds, tests, benchmarks and runs with.
# apt-get only; safe to run again. Must run as root (or through sudo).
set -euo pipefail

packages=(
  # toolchain
  build-essential cmake ninja-build pkg-config git
  # libraries
  libeigen3-dev libpcap-dev libgeographiclib-dev libserialport-dev libspdlog-dev
  libyaml-cpp-dev libcli11-dev
  # LCM: C/C++ library, lcm-gen, Java types for lcm-spy
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java default-jdk-headless
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # the soak's witness of the machine's own wake-up delays (cyclictest)
  rt-tests
  # fuzzing and sanitizers (clang's libFuzzer and runtimes); the clang build and the format check
  clang libclang-rt-14-dev clang-format
  # systemd-analyze for the unit checks; the service tests boot systemd in namespaces
  # (unshare, nsenter: util-linux; ip: iproute2) and read lcm-logger logs with Python
  systemd util-linux iproute2 python3
  # the man pages (from --help) and the .deb (cpack: dpkg-shlibdeps)
  help2man dpkg-dev
  # independent readers of `trajroi export`'s files in the tests: PCL's tools, Open3D
  pcl-tools python3-open3d
  # trajroi view: three.js for its page; the browser tests' headless chromium and its driver
  libjs-three chromium chromium-driver
  # the corrections tests: RTKLIB's str2str as a real NTRIP caster and TCP server, socat as
  # a UDP sender (str2str 2.4.3 b34 has no UDP output); chronyd reads trajroid's SHM refclock
  rtklib socat chrony
  # the LAS export test: PROJ (python3-pyproj) places the expected points (node runs copc.js: below)
  python3-pyproj
)

if [ "$(id -u)" -ne 0 ]; then
  SUDO=sudo
else
  SUDO=
fi

export DEBIAN_FRONTEND=noninteractive
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js and npm run the LAS test's reader (copc.js, from the npm registry): Debian's, unless the
# machine already has a Node.js with npm (its own packages must not be replaced).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi
if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
