#!/usr/bin/env bash
# Every channel trajroid publishes decodes the way lcm-spy decodes it (its LCMTypeDatabase
# with the project's type jar on the class path): a simulated run replayed through the
# daemon while SpyDecodeCheck listens. Usage: spy_check.sh TRAJROI TRAJROID SCENARIO CLASSPATH
set -euo pipefail
trajroi=$1 trajroid=$2 scenario=$3 classpath=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
url='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304'
prefix="SPYCHECK_$$"
"$trajroi" sim --quiet --scenario "$scenario" --out "$dir/run" >/dev/null
cp "$dir/run/trajroid.yaml" "$dir/run/spy.yaml"
cat >>"$dir/run/spy.yaml" <<YAML
lcm:
  channels: {points: ${prefix}_POINTS, pose: ${prefix}_POSE, roi: ${prefix}_ROI, status: ${prefix}_STATUS, trajectory: ${prefix}_TRAJECTORY}
YAML
java -cp "$classpath" SpyDecodeCheck "$url" 12 "${prefix}_POINTS" "${prefix}_POSE" "${prefix}_ROI" "${prefix}_STATUS" \
  >"$dir/check.txt" &
checker=$!
sleep 2  # the JVM up and subscribed
"$trajroid" --config "$dir/run/spy.yaml" --replay "$dir/run" --rate 4 --lcm-url "$url" 2>"$dir/trajroid.log" || {
  cat "$dir/trajroid.log" >&2
  exit 1
}
status=0
wait "$checker" || status=$?
grep "^${prefix}" "$dir/check.txt" || true
exit "$status"
