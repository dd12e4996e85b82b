#!/usr/bin/env bash
# Runs COMMAND… in a network namespace of its own: its loopback up, with the multicast route
# LCM needs (source 127.0.0.1), so LCM traffic of a test never meets the machine's or another
# test's. Needs root, unshare and ip. Usage: own_network.sh COMMAND…
set -euo pipefail
if [ "${TRAJROI_OWN_NETWORK:-}" != "$$" ]; then
  exec unshare --net /bin/bash -c 'TRAJROI_OWN_NETWORK=$$ exec /bin/bash "$0" "$@"' "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo src 127.0.0.1
exec "$@"
