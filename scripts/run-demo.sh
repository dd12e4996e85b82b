#!/usr/bin/env bash
# The README's main command: installs every dependency, builds, and runs trajroi's main job
# on its embedded defaults, no hardware needed:
#   1. the paper's artificial-frame experiment (Tables 3 and 5);
#   2. the bundled factory scenario simulated (VLP-16 pcap, u-blox and VN-100 recordings) and
#      evaluated at the paper's keyframes (Tables 9 and 11, the Table 20 picture);
#   3. the product: the factory run replayed through the trajroid daemon in real time (or
#      TRAJROI_DEMO_RATE=max|N), publishing over LCM on loopback with a status line each second
#      and a final summary; `trajroi watch` listens and scores the published sweeps against the
#      scenario's truth (precision, recall). Watch it live in another terminal: ./build/release/trajroi-spy
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/install-deps.sh

cmake --preset release
cmake --build --preset release -j"$jobs" --target trajroi trajroid
mkdir -p out
./build/release/tools/trajroi eval artificial --svg out/svg
echo
./build/release/tools/trajroi sim --scenario config/scenarios/factory.yaml --out out/runs/factory
./build/release/tools/trajroi eval keyframes --scenario out/runs/factory --svg out/keyframes
./build/release/tools/trajroi render --scenario out/runs/factory --keyframe keyframe2 --out out/table20_keyframe2.svg
echo
echo "Pictures: out/svg/*.svg (artificial frames), out/keyframes/*.svg, out/table20_keyframe2.svg"
echo
rate=${TRAJROI_DEMO_RATE:-10}
echo "trajroid: replaying out/runs/factory at --rate $rate over LCM udpm://239.255.76.67:7667?ttl=0"
./build/release/tools/trajroi watch --run out/runs/factory --lcm-url 'udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216' \
  --seconds 0 >out/watch.txt &
watcher=$!
sleep 1
./build/release/daemon/trajroid --config out/runs/factory/trajroid.yaml --replay out/runs/factory --rate "$rate"
wait "$watcher" || true
cat out/watch.txt
