# A real systemd, booted as PID 1 of private PID, mount, network and IPC namespaces, for the
# service tests. Source this file; then:
#   nsd_boot              boot it (waits until it is running); ends it at exit
#   nsd COMMAND…          run a command inside (its PID, mount and network namespaces)
#   nsd_install_unit FILE [NAME]   copy a unit into its /run/systemd/system and daemon-reload
#   nsd_end               end it (kill its PID 1)
#
# The namespace gets its own /tmp and /run (tmpfs) before anything else: systemd-tmpfiles
# empties /tmp at boot, and must never see the machine's. Its journal and the /var folders a
# DynamicUser service writes are tmpfs of its own as well, and the units that would change the
# machine itself (sysctl, modules, binfmt, users, tmpfiles, udev) are masked. Its network is a loopback of its own,
# up, with the multicast route LCM needs and the addresses in NSD_ADDRESSES (default none) on it.
# Needs root, unshare/nsenter (util-linux), ip (iproute2) and /lib/systemd/systemd.

# shellcheck source=../lib/skip.sh
source "$(dirname "${BASH_SOURCE[0]}")/../lib/skip.sh"

NSD_PID1=""
NSD_UNSHARE=""
# Redefine to clean up the test's own processes before the namespace ends.
nsd_on_exit() { :; }

nsd_require() {
  local missing=()
  [ "$(id -u)" -eq 0 ] || missing+=("root")
  for tool in unshare nsenter ip findmnt; do command -v "$tool" >/dev/null || missing+=("$tool"); done
  [ -x /lib/systemd/systemd ] || missing+=("/lib/systemd/systemd")
  [ ${#missing[@]} -eq 0 ] || skip_or_fail "nsd: cannot boot a namespaced systemd here: missing ${missing[*]}"
}

nsd_boot() {
  nsd_require
  local addresses="${NSD_ADDRESSES:-}"
  # The script PID 1 runs: the private /tmp and /run first (and checked empty), then the
  # network, then systemd. Any failure ends it before systemd starts.
  unshare --pid --fork --mount-proc --mount --propagation private --net --ipc \
    /bin/bash -c '
      set -euo pipefail
      mount -t tmpfs tmpfs /tmp
      mount -t tmpfs tmpfs /run
      [ -z "$(ls -A /tmp)" ] && [ -z "$(ls -A /run)" ]
      [ "$(findmnt -n -o FSTYPE /tmp)" = tmpfs ]
      # What this systemd writes below /var stays in the namespace too: its journal, the
      # DynamicUser state, and /var/tmp (which systemd-tmpfiles also cleans).
      for spec in /var/tmp:1777 /var/log/journal:2755 /var/lib/private:0700 /var/cache/private:0700 \
                  /var/log/private:0700; do
        dir=${spec%:*}
        [ -d "$dir" ] || mkdir -p -m "${spec#*:}" "$dir"
        mount -t tmpfs -o "mode=${spec#*:}" tmpfs "$dir"
      done
      # Units that would change the machine rather than the namespace (kernel modules, binfmt,
      # sysctl, users, tmpfiles in /etc and /var, udev, the root mount) are masked.
      mkdir -p /run/systemd/system
      for unit in systemd-sysctl.service systemd-modules-load.service kmod-static-nodes.service \
                  systemd-binfmt.service proc-sys-fs-binfmt_misc.automount systemd-sysusers.service \
                  systemd-tmpfiles-setup.service systemd-tmpfiles-setup-dev.service systemd-tmpfiles-clean.timer \
                  systemd-remount-fs.service systemd-udevd.service systemd-udev-trigger.service \
                  systemd-hwdb-update.service systemd-random-seed.service systemd-update-utmp.service \
                  systemd-firstboot.service systemd-machine-id-commit.service ldconfig.service \
                  systemd-journal-catalog-update.service systemd-update-done.service systemd-pstore.service; do
        ln -s /dev/null "/run/systemd/system/$unit"
      done
      ip link set lo up
      ip link set lo multicast on
      ip route add 224.0.0.0/4 dev lo src 127.0.0.1
      for a in '"$addresses"'; do ip addr add "$a/32" dev lo; done
      exec /lib/systemd/systemd --system --unit=basic.target' \
    </dev/null >"${NSD_LOG:-/dev/null}" 2>&1 &
  NSD_UNSHARE=$!
  trap 'nsd_on_exit || true; nsd_end' EXIT
  local i
  for i in $(seq 1 100); do
    NSD_PID1=$(pgrep -P "$NSD_UNSHARE" -x systemd || true)
    [ -n "$NSD_PID1" ] && break
    if ! kill -0 "$NSD_UNSHARE" 2>/dev/null; then
      echo "nsd: the namespace's PID 1 ended before systemd started" >&2
      exit 1
    fi
    sleep 0.1
  done
  [ -n "$NSD_PID1" ] || { echo "nsd: systemd did not start" >&2; exit 1; }
  local state=""
  for i in $(seq 1 300); do
    state=$(nsd systemctl is-system-running 2>/dev/null || true)
    case "$state" in running | degraded) break ;; esac
    sleep 0.1
  done
  case "$state" in
    running | degraded) echo "nsd: systemd $(nsd systemctl --version | head -1 | cut -d' ' -f2) is PID 1 of a private namespace (host PID $NSD_PID1), $state" ;;
    *) echo "nsd: systemd did not finish booting (state '$state')" >&2; exit 1 ;;
  esac
}

nsd() {
  nsenter -t "$NSD_PID1" -p -m -n -i "$@"
}

nsd_install_unit() {
  local file=$1 name=${2:-$(basename "$1")}
  nsd mkdir -p /run/systemd/system
  nsd sh -c "cat > /run/systemd/system/$name" <"$file"
  nsd systemctl daemon-reload
}

# A drop-in for UNIT from stdin, named NAME.conf.
nsd_drop_in() {
  local unit=$1 name=$2
  nsd mkdir -p "/run/systemd/system/$unit.d"
  nsd sh -c "cat > /run/systemd/system/$unit.d/$name.conf"
  nsd systemctl daemon-reload
}

# Idempotent: the exit trap calls it again.
nsd_end() {
  if [ -n "$NSD_PID1" ]; then
    kill -KILL "$NSD_PID1" 2>/dev/null || true
  fi
  if [ -n "$NSD_UNSHARE" ]; then
    wait "$NSD_UNSHARE" 2>/dev/null || true
  fi
  NSD_PID1=""
  NSD_UNSHARE=""
}
