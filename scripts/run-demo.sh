#!/usr/bin/env bash
# The README's main command: installs every dependency, builds, and runs trajroi's main job
# on its embedded default — the paper's artificial-frame experiment (Tables 3 and 5), with
# pictures of every row written to out/svg/.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/install-deps.sh

cmake --preset release
cmake --build --preset release -j"$jobs" --target trajroi
mkdir -p out
./build/release/tools/trajroi eval artificial --svg out/svg "$@"
echo
echo "Pictures of every row: out/svg/*.svg"
