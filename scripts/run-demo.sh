#!/usr/bin/env bash
# The README's main command: installs every dependency, builds, and runs trajroi's main job
# on its embedded defaults — the paper's artificial-frame experiment (Tables 3 and 5), then
# the bundled factory scenario simulated and evaluated at the paper's keyframes (Tables 9
# and 11) with the Table 20 picture; pictures go to out/.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/install-deps.sh

cmake --preset release
cmake --build --preset release -j"$jobs" --target trajroi
mkdir -p out
./build/release/tools/trajroi eval artificial --svg out/svg "$@"
echo
./build/release/tools/trajroi sim --scenario config/scenarios/factory.yaml --out out/runs/factory
./build/release/tools/trajroi eval keyframes --scenario out/runs/factory --svg out/keyframes
./build/release/tools/trajroi render --scenario out/runs/factory --keyframe keyframe2 --out out/table20_keyframe2.svg
echo
echo "Pictures: out/svg/*.svg (artificial frames), out/keyframes/*.svg, out/table20_keyframe2.svg"
