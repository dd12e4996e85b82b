#!/usr/bin/env bash
# Checks a trajroid unit: `systemd-analyze verify` is clean and the offline security exposure
# is at most the given score. With DROP_IN files, checks the unit as systemd would load it
# with them (their [Service] settings after the unit's own).
# Usage: check-unit.sh UNIT MAX_EXPOSURE [DROP_IN...]
set -euo pipefail
unit=$1
max=$2
shift 2
if [ $# -gt 0 ]; then
  merged_dir=$(mktemp -d)
  trap 'rm -rf "$merged_dir"' EXIT
  merged="$merged_dir/$(basename "$unit")"
  {
    sed '/^\[Install\]/,$d' "$unit"
    for drop_in in "$@"; do sed '1,/^\[Service\]/d' "$drop_in"; done
    sed -n '/^\[Install\]/,$p' "$unit"
  } >"$merged"
  unit=$merged
fi
if ! command -v systemd-analyze >/dev/null; then
  echo "check-unit: systemd-analyze not installed (scripts/install-deps.sh installs it)" >&2
  exit 1
fi
verify=$(systemd-analyze verify "$unit" 2>&1 || true)
# Complaints about other units of this machine are not ours.
ours=$(grep -F "$(basename "$unit")" <<<"$verify" || true)
if [ -n "$ours" ]; then
  echo "check-unit: systemd-analyze verify:" >&2
  echo "$ours" >&2
  exit 1
fi
score=$(systemd-analyze security --offline=true "$unit" 2>&1 | sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
if [ -z "$score" ]; then
  echo "check-unit: no exposure score from systemd-analyze security" >&2
  exit 1
fi
echo "check-unit: $unit verifies; exposure $score (goal <= $max)"
awk -v s="$score" -v m="$max" 'BEGIN { exit !(s <= m) }'
