# The rule for a shell test that cannot run on this machine (a tool, a privilege or a capture
# missing): skipped outside CI (ctest's SKIP_RETURN_CODE 77), a failure under CI=true, where
# everything it needs is installed. Source this file; then:
#   skip_or_fail REASON…     say why on stderr and end the test
#   require_netns NAME       what a test making network namespaces needs: root, unshare and ip

skip_or_fail() {
  echo "SKIP: $*" >&2
  if [ "${CI:-}" = true ]; then exit 1; fi
  exit 77
}

require_netns() {
  if [ "$(id -u)" -ne 0 ] || ! command -v unshare >/dev/null || ! command -v ip >/dev/null; then
    skip_or_fail "$1: needs root, unshare and ip"
  fi
}
