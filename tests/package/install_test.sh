#!/usr/bin/env bash
# `cmake --install` stays within its prefix and honours DESTDIR; what it installs is usable:
# the unit and trajroi-spy name the prefix's paths, the C++ subscriber example builds against
# the installed CMake package and, with the Python one on the installed types, receives the
# clouds of a replay (in a network namespace of its own).
# Usage: install_test.sh BUILD TRAJROI WORK
set -euo pipefail
build=$1 trajroi=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.txt"
outside=$(grep -v "^$prefix/" "$build/install_manifest.txt" || true)
[ -z "$outside" ] || fail "installed outside the prefix: $outside"
echo "cmake --install --prefix: $(wc -l <"$build/install_manifest.txt") files, all below the prefix"
unit=$prefix/lib/systemd/system/trajroid.service
grep -q "^ExecStart=$prefix/bin/trajroid --config $prefix/etc/trajroi/trajroid.yaml$" "$unit" ||
  fail "the unit does not name the prefix's paths: $(grep ^ExecStart= "$unit")"
grep -q "^JAR=\"$prefix/share/java/trajroi_lcmtypes.jar\"" "$prefix/bin/trajroi-spy" || fail "trajroi-spy's jar path"
for f in etc/trajroi/trajroid.yaml lib/sysctl.d/60-trajroi-lcm.conf share/man/man1/trajroid.1.gz \
  share/man/man1/trajroi.1.gz share/java/trajroi_lcmtypes.jar share/trajroi/lcmtypes/points_t.lcm \
  include/trajroi/points_t.hpp include/trajroi_points_t.h lib/cmake/trajroi/trajroiConfig.cmake \
  lib/python3/dist-packages/trajroi/points_t.py share/doc/trajroi/LICENSE share/doc/trajroi/examples/99-trajroi-serial.rules; do
  [ -f "$prefix/$f" ] || fail "not installed: $f"
done
"$prefix/bin/trajroid" --version | grep -qx "trajroid [0-9.]*" || fail "trajroid --version"

staged=$work/destdir
DESTDIR=$staged cmake --install "$build" --prefix /opt/trajroi-destdir-test >/dev/null
while read -r f; do
  [ -e "$staged$f" ] || fail "DESTDIR: $f not staged"
done <"$build/install_manifest.txt"
[ ! -e /opt/trajroi-destdir-test ] || fail "DESTDIR: files written to /opt/trajroi-destdir-test"
echo "DESTDIR=… cmake --install: $(wc -l <"$build/install_manifest.txt") files, all staged, none outside"

# The subscribers of docs/lcm.md, on the installed package.
cmake -S "$prefix/share/doc/trajroi/examples" -B "$work/subscriber" -DCMAKE_PREFIX_PATH="$prefix" >"$work/cmake.txt" 2>&1 ||
  fail "the example does not configure against the installed package: $(tail -20 "$work/cmake.txt")"
cmake --build "$work/subscriber" >>"$work/cmake.txt" 2>&1 || fail "the example does not build: $(tail -20 "$work/cmake.txt")"
"$trajroi" sim --quiet --scenario "$(dirname "$0")/../daemon/corridor.yaml" --out "$work/run" >/dev/null 2>&1
if [ "$(id -u)" -ne 0 ] || ! command -v unshare >/dev/null; then
  echo "not root: the subscribers are built, not run" >&2
  [ "${CI:-}" = true ] && exit 1
  exit 0
fi
bash "$(dirname "$0")/../systemd/own_network.sh" /bin/bash -c '
  set -euo pipefail
  url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608"
  "$1/subscriber/subscriber" "$url" >"$1/cpp.txt" 2>&1 &
  cpp=$!
  PYTHONPATH="$2/lib/python3/dist-packages" "${PYTHON:-python3}" "$2/share/doc/trajroi/examples/subscriber.py" "$url" \
    >"$1/python.txt" 2>&1 &
  python=$!
  sleep 1
  "$2/bin/trajroid" --config "$1/run/trajroid.yaml" --replay "$1/run" --rate 4 2>"$1/trajroid.log"
  sleep 1
  kill "$cpp" "$python"
  wait || true' _ "$work" "$prefix"
published=$(sed -n 's/.*summary: .* published \([0-9]*\) withheld.*/\1/p' "$work/trajroid.log")
cpp=$(grep -c "^sweep .* points kept, pose valid$" "$work/cpp.txt" || true)
python=$(grep -c "^sweep .* points kept, pose valid$" "$work/python.txt" || true)
echo "subscribers on the installed package: C++ received $cpp, Python $python of $published clouds"
head -2 "$work/cpp.txt"
[ "$cpp" -ge $((published * 9 / 10)) ] || fail "the C++ subscriber received $cpp of $published: $(tail -3 "$work/cpp.txt")"
[ "$python" -ge $((published * 9 / 10)) ] || fail "the Python subscriber received $python of $published: $(tail -3 "$work/python.txt")"
echo "PASS"
