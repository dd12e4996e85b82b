#!/usr/bin/env bash
# trajroid names, at start-up, a ttl=0 LCM group whose route cuts the clouds' datagrams into
# IP fragments, with the interface, its MTU and the kernel's own count of fragments per
# datagram (its FragCreates counter over one 65 507-byte datagram sent to the group), and says
# nothing when the group goes over lo or is meant to leave the host (ttl=1). All in a network
# namespace of its own: a veth pair of MTU 1 500 carries the group, then lo with a route of
# mtu 1 400, then lo itself with an MTU of 1 500, then lo as it is; over lo, the line says to
# mend the route's or lo's MTU rather than to route the group over lo.
# Usage: lcm_route_test.sh TRAJROI TRAJROID SCENARIO WORK
set -euo pipefail
trajroi=$1 trajroid=$2 scenario=$3 work=$4
# shellcheck source=../lib/skip.sh
source "$(dirname "$0")/../lib/skip.sh"
require_netns lcm_route_test
rm -rf "$work"
mkdir -p "$work"
"$trajroi" sim --quiet --scenario "$scenario" --out "$work/run" >/dev/null

unshare --net /bin/bash -s "$trajroid" "$work" "${PYTHON:-python3}" <<'NETNS'
set -euo pipefail
trajroid=$1 work=$2 python=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
# The kernel's fragments for one datagram of the outlet's largest size, sent to the group (ttl=0).
kernel_fragments() {
  "$python" - <<'PY'
import socket
def created():
    rows = [line.split() for line in open("/proc/net/snmp") if line.startswith("Ip:")]
    return int(rows[1][rows[0].index("FragCreates")])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
before = created()
s.sendto(b"\0" * 65507, ("239.255.76.67", 7667))
print(created() - before)
PY
}
replay() {  # label [trajroid options…]: the log of an as-fast replay
  local label=$1
  shift
  "$trajroid" --config "$work/run/trajroid.yaml" --replay "$work/run" --rate max "$@" >"$work/$label.log" 2>&1 ||
    fail "$label: trajroid exited with $? ($(tail -n 3 "$work/$label.log"))"
  grep -q "summary: .* published [1-9]" "$work/$label.log" || fail "$label: no cloud published"
}
advice() { grep "ttl=0 keeps the datagrams on this host" "$work/$1.log" || true; }
# label interface mtu remedy: a replay's line names the interface, its MTU, the kernel's own
# fragment count for one datagram over the route as it now is, and the remedy.
named() {
  local label=$1 interface=$2 mtu=$3 remedy=$4 fragments line
  fragments=$(kernel_fragments)
  echo "route over $interface (MTU $mtu): the kernel cut a 65 507-byte datagram into $fragments fragments"
  [ "$fragments" -gt 1 ] || fail "$label: the kernel did not fragment the datagram ($fragments)"
  replay "$label"
  line=$(advice "$label")
  echo "trajroid: ${line#*info  }"
  grep -qF "goes through $interface (MTU $mtu): each 64 KB datagram of a cloud is cut into $fragments IP fragments" <<<"$line" ||
    fail "$label: no line naming $interface, its MTU of $mtu and the kernel's $fragments fragments"
  grep -qF "$remedy" <<<"$line" || fail "$label: the line does not give the remedy '$remedy'"
}

ip link set lo up
ip link add trajroi0 mtu 1500 type veth peer name trajroi1 mtu 1500
ip addr add 10.200.0.1/24 dev trajroi0
ip link set trajroi1 up
ip link set trajroi0 up
ip route add 224.0.0.0/4 dev trajroi0
named veth trajroi0 1500 "route the group over lo (ip link set lo multicast on; ip route add 239.255.76.67/32 dev lo"

replay ttl1 --lcm-url "udpm://239.255.76.67:7667?ttl=1"
[ -z "$(advice ttl1)" ] || fail "advice for a group meant to leave the host (ttl=1)"

# A route's own mtu is the one the kernel fragments by (lo's 65 536 would not); over lo the
# remedy is that mtu, not routing the group over lo again.
ip link set lo multicast on
ip route replace 224.0.0.0/4 dev lo mtu 1400
named lo1400 lo 1400 "the route over lo sets that MTU itself: make it again without mtu"
! grep -q "ip route add" <<<"$(advice lo1400)" || fail "lo1400: the line says to route the group over lo again"

# lo's own MTU made small (the route without one): the remedy is lo's MTU.
ip route replace 224.0.0.0/4 dev lo
ip link set lo mtu 1500
named lo1500 lo 1500 "ip link set lo mtu 65536"
ip link set lo mtu 65536

ip route replace 224.0.0.0/4 dev lo
[ "$(kernel_fragments)" -eq 0 ] || fail "the kernel still fragments over lo"
replay lo
[ -z "$(advice lo)" ] || fail "advice for a group routed over lo"
echo "PASS: named over trajroi0, over lo's route of mtu 1400 and over lo of MTU 1500 with the kernel's fragments and each its remedy; nothing said for ttl=1 or over lo"
NETNS
