# SPDX-License-Identifier: Apache-2.0
# Two emulated sites joined by an emulated link (issue 14). Source it:
#
#   source tests/network/sites.sh
#   sites_require || exit $?      # 77 (skip) without root, ip, ethtool or namespaces
#   sites_up lk3 "$OUT"           # namespaces lk3-a, lk3-b, lk3-link; an EXIT trap removes
#                                 # them (it replaces yours: call sites_down from your own)
#   link_start --delay 50 --loss 10 --duration 60   # link_emu options (top of link_emu.c)
#   run_in_site a  "$BUILD/server/viscera-server" ... &   # VISCERA_IFACE etc. already set
#   run_in_site b  "$BUILD/client/haptic/viscera-haptic" ... &
#   link_stop                     # stops the emulator, prints its per-direction counts
#   link_count 'a->b' out         # one of those counts (quote the direction)
#   sites_down                    # also run by the EXIT trap sites_up installs
#
# Layout: site a (namespace PFX-a) has interface PFXa0 = 10.231.0.1/24 and lo;
# site b (PFX-b) has PFXb0 = 10.231.0.2/24 and lo; the link namespace PFX-link
# holds the far ends PFXla and PFXlb of the two veth pairs, without addresses,
# and runs link_emu between them. The sites are one Ethernet segment (ARP and
# multicast cross the emulator like any frame). Transmit checksum and
# segmentation offloads are off on all four veths: a forwarded frame keeps the
# checksum its sender wrote. IPv6 is off and the two addresses are static
# neighbours, so the link carries only the programs' own frames (and their
# multicast). Nothing is created outside these namespaces.
#
# Inside a site, run_in_site exports VISCERA_IFACE (the site's interface),
# VISCERA_PEER (the other site's address) and VISCERA_SITE_ADDR (its own), which
# deploy/cyclonedds-site.xml and deploy/cyclonedds-lan.xml read.
# env: LINK_EMU (the emulator binary; default $BUILD/tests/network/link_emu).

SITES_PFX="" SITES_DIR="" LINK_PID=""
SITE_A_ADDR=10.231.0.1 SITE_B_ADDR=10.231.0.2

# 0 when sites can be made here; otherwise prints why and returns 77.
sites_require() {
  if [ "$(id -u)" != 0 ]; then echo "SKIP: network tests need root (network namespaces)"; return 77; fi
  local t
  for t in ip ethtool; do
    command -v "$t" >/dev/null || { echo "SKIP: '$t' missing (deploy/install_deps.sh installs it)"; return 77; }
  done
  local probe="lkprobe$$"
  if ! ip netns add "$probe" 2>/dev/null; then echo "SKIP: cannot create network namespaces"; return 77; fi
  ip netns del "$probe"
  return 0
}

_sites_veth() { # _sites_veth SITE_IF SITE_NS LINK_IF
  ip link add "$1" netns "$2" type veth peer name "$3" netns "$SITES_PFX-link" || return 1
  ip -n "$2" link set "$1" up && ip -n "$SITES_PFX-link" link set "$3" up promisc on || return 1
  # Offloads off on both ends: the emulator copies frames as it reads them.
  ip netns exec "$2" ethtool -K "$1" tx off tso off gso off gro off >/dev/null 2>&1 || return 1
  ip netns exec "$SITES_PFX-link" ethtool -K "$3" tx off tso off gso off gro off >/dev/null 2>&1 || return 1
}

# sites_up PFX DIR: PFX short (<= 6 chars: interface names stay <= 15), DIR for logs.
sites_up() {
  SITES_PFX="$1" SITES_DIR="$2"
  mkdir -p "$SITES_DIR"
  trap 'sites_down' EXIT
  sites_down quiet
  local ns
  for ns in a b link; do ip netns add "$SITES_PFX-$ns" || return 1; done
  for ns in a b link; do
    ip -n "$SITES_PFX-$ns" link set lo up || return 1
    # No IPv6 on the sites: its autoconfiguration and MLD frames would cross the
    # link at times of their own and shift the emulator's seeded decisions.
    ip netns exec "$SITES_PFX-$ns" sysctl -qw net.ipv6.conf.all.disable_ipv6=1 net.ipv6.conf.default.disable_ipv6=1 \
      >/dev/null 2>&1 || true
  done
  _sites_veth "${SITES_PFX}a0" "$SITES_PFX-a" "${SITES_PFX}la" || return 1
  _sites_veth "${SITES_PFX}b0" "$SITES_PFX-b" "${SITES_PFX}lb" || return 1
  ip -n "$SITES_PFX-a" addr add "$SITE_A_ADDR/24" dev "${SITES_PFX}a0" || return 1
  ip -n "$SITES_PFX-b" addr add "$SITE_B_ADDR/24" dev "${SITES_PFX}b0" || return 1
  # Static neighbours: no ARP frames on the link either.
  local mac_a mac_b
  mac_a=$(ip netns exec "$SITES_PFX-a" cat "/sys/class/net/${SITES_PFX}a0/address") || return 1
  mac_b=$(ip netns exec "$SITES_PFX-b" cat "/sys/class/net/${SITES_PFX}b0/address") || return 1
  ip -n "$SITES_PFX-a" neigh replace "$SITE_B_ADDR" lladdr "$mac_b" dev "${SITES_PFX}a0" nud permanent || return 1
  ip -n "$SITES_PFX-b" neigh replace "$SITE_A_ADDR" lladdr "$mac_a" dev "${SITES_PFX}b0" nud permanent || return 1
  # Multicast (Cyclone's SPDP in the LAN configuration) leaves by the site's interface.
  ip -n "$SITES_PFX-a" route add 224.0.0.0/4 dev "${SITES_PFX}a0" || return 1
  ip -n "$SITES_PFX-b" route add 224.0.0.0/4 dev "${SITES_PFX}b0" || return 1
}

# sites_down [quiet]: stops the emulator and every process still in the sites, removes the namespaces.
sites_down() {
  [ -n "$SITES_PFX" ] || return 0
  [ -z "$LINK_PID" ] || link_stop >/dev/null 2>&1 || true
  local ns p
  for ns in a b link; do
    { ip netns pids "$SITES_PFX-$ns" 2>/dev/null || true; } | while read -r p; do kill -9 "$p" 2>/dev/null || true; done
    ip netns del "$SITES_PFX-$ns" 2>/dev/null || true
  done
  [ "${1:-}" = quiet ] || echo "sites: $SITES_PFX-{a,b,link} removed"
}

# run_in_site a|b|link COMMAND...: runs COMMAND in that site with its network variables
# (run_in_site ... & gives in $! the pid of COMMAND itself: in any subshell it execs,
# so do not call it inside ( ... ) with commands after it).
run_in_site() {
  local site="$1" ifc peer self
  shift
  case "$site" in
    a) ifc="${SITES_PFX}a0" self=$SITE_A_ADDR peer=$SITE_B_ADDR ;;
    b) ifc="${SITES_PFX}b0" self=$SITE_B_ADDR peer=$SITE_A_ADDR ;;
    link) ifc="" self="" peer="" ;;
    *) echo "run_in_site: no site '$site'" >&2; return 2 ;;
  esac
  # In a subshell (run_in_site ... &, $(...)) exec, so that $! is the program itself
  # and a signal sent to it reaches it.
  if [ "$BASHPID" != "$$" ]; then
    exec ip netns exec "$SITES_PFX-$site" env VISCERA_IFACE="$ifc" VISCERA_PEER="$peer" VISCERA_SITE_ADDR="$self" "$@"
  fi
  ip netns exec "$SITES_PFX-$site" env VISCERA_IFACE="$ifc" VISCERA_PEER="$peer" VISCERA_SITE_ADDR="$self" "$@"
}

# link_start EMULATOR-OPTIONS...: starts link_emu in the link namespace (log SITES_DIR/link.log)
# and returns once it forwards. Give --duration longer than the test needs.
link_start() {
  local emu="${LINK_EMU:-${BUILD:-build}/tests/network/link_emu}" ready="$SITES_DIR/link.ready" i
  rm -f "$ready"
  ip netns exec "$SITES_PFX-link" "$emu" --a "${SITES_PFX}la" --b "${SITES_PFX}lb" --ready "$ready" "$@" \
    > "$SITES_DIR/link.log" 2>&1 &
  LINK_PID=$!
  for ((i = 0; i < 100; i++)); do
    [ -f "$ready" ] && return 0
    kill -0 "$LINK_PID" 2>/dev/null || break
    sleep 0.05
  done
  echo "link_start: the emulator did not start:" >&2
  cat "$SITES_DIR/link.log" >&2
  LINK_PID=""
  return 1
}

# link_stop: stops the emulator and prints its report.
link_stop() {
  [ -n "$LINK_PID" ] || return 0
  kill -TERM "$LINK_PID" 2>/dev/null || true
  wait "$LINK_PID" 2>/dev/null || true
  LINK_PID=""
  grep '^link ' "$SITES_DIR/link.log" || true
}

# link_count 'a->b'|'b->a' FIELD: a count from the last emulator report (in, out, loss, ...).
link_count() {
  sed -n "s/^link $1: .* $2=\([0-9]*\).*/\1/p; s/^link $1: $2=\([0-9]*\).*/\1/p" "$SITES_DIR/link.log" | tail -1
}
