#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deb_check.sh: the .deb installed with apt on a clean Debian 12 (issue 18).
#
# Builds the package with `cpack -G DEB` in a build directory (or takes one
# given with --deb), makes a clean Debian 12 root (debootstrap
# --variant=minbase bookworm, from the Debian mirror this machine's apt uses),
# copies the .deb in and, inside that root (chroot, /proc mounted), runs
#   apt-get install -y ./viscera_*.deb     every dependency from Debian alone
# then, from /root/elsewhere (not a source tree), with CYCLONEDDS_URI and
# VISCERA_DATA_DIR unset, a short session from the installed files only:
#   viscera-server --scene kidney_xpbd.yaml, viscera-recorder, a scripted
#   viscera-haptic --trajectory palpate_kidney.traj, then viscera-report
# on the loopback of a network namespace of its own (unshare --net: no
# other process on this machine sees it; domain $VISCERA_DOMAIN, else the
# binaries' default). It checks: the server took the installed
# scene, a client with nobody to talk to names the installed loopback
# configuration, the trainee's peak force is above 0.5 N, the recording holds
# samples, the report (HTML + CSV) was written, every binary's man page is
# under /usr/share/man/man1 (minbase has no man-db). Then (unless --no-systemd)
# it installs systemd and reinstalls the .deb: the postinst creates the
# `viscera` user with systemd-sysusers. Last, `apt-get remove viscera` must
# leave no /usr/bin/viscera-* and no /usr/share/viscera.
#
# usage: deb_check.sh [--build DIR] [--deb FILE] [--cache DIR] [--mirror URL]
#                     [--no-systemd] [--keep]
#   --build DIR   build directory to run cpack in (default: build/ of the repo)
#   --deb FILE    use this .deb instead of building one
#   --cache DIR   kept between runs (default /var/cache/viscera-debcheck): the
#                 minbase root as a tarball and the Debian packages apt
#                 downloaded, so a re-run downloads nothing (delete it to
#                 measure a first run again)
#   --mirror URL  Debian mirror (default: the first bookworm URI in
#                 /etc/apt/sources.list{,.d/*}, else http://deb.debian.org/debian)
#   --no-systemd  skip the systemd / sysusers step
#   --keep        keep the scratch root (printed) instead of removing it
# Needs root, debootstrap, chroot, unshare, ip and access to the mirror.
# Everything it creates, except the cache, is removed on exit (trap): the
# scratch directory /tmp/debcheck.XXXXXX, its mounts, any process left in it.
# Exit 0 pass, 1 a check failed (named), 2 bad usage, 77 not root or a
# tool missing (ctest's skip code).
set -euo pipefail
ROOT_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD="$ROOT_DIR/build" DEB="" CACHE=/var/cache/viscera-debcheck MIRROR="" SYSTEMD=1 KEEP=0
while [ $# -gt 0 ]; do
  case "$1" in
  --build) BUILD=$2; shift 2 ;;
  --deb) DEB=$(realpath "$2"); shift 2 ;;
  --cache) CACHE=$2; shift 2 ;;
  --mirror) MIRROR=$2; shift 2 ;;
  --no-systemd) SYSTEMD=0; shift ;;
  --keep) KEEP=1; shift ;;
  -h | --help) sed -n '3,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
  *) echo "deb_check.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" = 0 ] || { echo "SKIP: deb_check.sh needs root (debootstrap, chroot)"; exit 77; }
DEBOOTSTRAP=$(command -v debootstrap || echo /usr/sbin/debootstrap)
[ -x "$DEBOOTSTRAP" ] || { echo "SKIP: debootstrap not installed (apt-get install debootstrap)"; exit 77; }
# The session runs in a network namespace of its own (unshare, ip), on the
# binaries' default domain unless VISCERA_DOMAIN is set.
for t in unshare ip chroot; do
  command -v $t > /dev/null || { echo "SKIP: $t not found (util-linux, iproute2)"; exit 77; }
done
DOMAIN=${VISCERA_DOMAIN:-}

# The mirror apt uses here: deb822 "URIs:" or one-line "deb URI bookworm".
apt_sources() {
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && cat "$f"
  done
  true
}
if [ -z "$MIRROR" ]; then
  MIRROR=$(apt_sources |
    awk '/^URIs:/ { u = $2 } /^Suites:/ && / bookworm( |$)/ && u { print u; exit }
         /^deb / && $3 == "bookworm" { print $2; exit }')
  MIRROR=${MIRROR:-http://deb.debian.org/debian}
fi
SECURITY=$(apt_sources |
  awk '/^URIs:/ { u = $2 } /^Suites:/ && /bookworm-security/ && u { print u; exit }
       /^deb / && $3 == "bookworm-security" { print $2; exit }')

T0=$(date +%s)
step() { echo "[$(($(date +%s) - T0)) s] $*"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

WORK=$(mktemp -d /tmp/debcheck.XXXXXX)
R="$WORK/root"
cleanup() {
  local rc=$?
  if [ -d "$R" ]; then
    # Processes left inside the root (a session that failed half-way): ours.
    for p in /proc/[0-9]*; do
      [ "$(readlink "$p/root" 2> /dev/null)" = "$R" ] && kill -9 "${p#/proc/}" 2> /dev/null || true
    done
    for m in "$R/proc" "$R/dev/pts" "$R/dev"; do
      mountpoint -q "$m" 2> /dev/null && umount -l "$m"
    done
  fi
  if [ "$KEEP" = 1 ]; then echo "kept: $R"; else rm -rf --one-file-system "$WORK"; fi
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# 1. The package.
if [ -z "$DEB" ]; then
  step "cpack -G DEB in $BUILD"
  (cd "$BUILD" && nice cpack -G DEB -B "$WORK/pkg") > "$WORK/cpack.log" 2>&1 ||
    { tail -20 "$WORK/cpack.log"; fail "cpack failed"; }
  DEB=$(ls "$WORK"/pkg/viscera_*.deb)
fi
[ -f "$DEB" ] || fail "no .deb: $DEB"
echo "package: $DEB ($(du -k "$DEB" | cut -f1) kB)"
echo "Depends: $(dpkg-deb -f "$DEB" Depends)"

# 2. A clean Debian 12 root: debootstrap once into the cache, unpacked per run.
mkdir -p "$CACHE/archives"
TARBALL="$CACHE/bookworm-minbase.tar"
if [ ! -f "$TARBALL" ]; then
  step "debootstrap --variant=minbase bookworm from $MIRROR (first run; cached in $TARBALL)"
  "$DEBOOTSTRAP" --variant=minbase bookworm "$WORK/boot" "$MIRROR" > "$WORK/debootstrap.log" 2>&1 ||
    { tail -20 "$WORK/debootstrap.log"; fail "debootstrap failed"; }
  rm -f "$WORK"/boot/var/cache/apt/archives/*.deb
  tar -C "$WORK/boot" -cf "$TARBALL.tmp" . && mv "$TARBALL.tmp" "$TARBALL"
  rm -rf --one-file-system "${WORK:?}/boot"
fi
step "unpacking the clean root into $R"
mkdir -p "$R"
tar -C "$R" -xf "$TARBALL"
{
  echo "deb $MIRROR bookworm main"
  echo "deb $MIRROR bookworm-updates main"
  [ -n "$SECURITY" ] && echo "deb $SECURITY bookworm-security main"
} > "$R/etc/apt/sources.list"
cp /etc/resolv.conf "$R/etc/resolv.conf" 2> /dev/null || true
# Keep apt's downloads for the next run (copied in and out; no bind mount).
cp "$CACHE"/archives/*.deb "$R/var/cache/apt/archives/" 2> /dev/null || true
cp "$DEB" "$R/root/"
mount -t proc proc "$R/proc"
[ -c "$R/dev/null" ] || { mount --bind /dev "$R/dev"; }

# Everything inside runs with a clean environment: no CYCLONEDDS_URI, no
# VISCERA_DATA_DIR, nothing of this machine's build.
in_root() {
  env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 DEBIAN_FRONTEND=noninteractive \
    chroot "$R" "$@"
}

# 3. apt-get install of the .deb: Debian alone must provide every dependency.
step "apt-get update"
in_root apt-get update > "$WORK/apt-update.log" 2>&1 || { tail "$WORK/apt-update.log"; fail "apt-get update failed"; }
step "apt-get install -y ./$(basename "$DEB")"
in_root sh -c "cd /root && apt-get install -y --no-install-recommends ./$(basename "$DEB")" > "$WORK/apt-install.log" 2>&1 ||
  { tail -30 "$WORK/apt-install.log"; fail "apt-get install of the .deb failed"; }
grep -E "^(Need to get|After this operation|[0-9]+ upgraded)" "$WORK/apt-install.log" || true
in_root dpkg -s viscera | grep -q "^Status: install ok installed" || fail "dpkg does not list viscera as installed"
cp -n "$R"/var/cache/apt/archives/*.deb "$CACHE/archives/" 2> /dev/null || true
rm -f "$CACHE/archives/$(basename "$DEB")"

# 4. A session from the installed files, from a directory of no source tree.
step "session from the installed files (domain ${DOMAIN:-default}, loopback of a private network namespace)"
cat > "$R/root/session.sh" << 'EOF'
set -u
mkdir -p /root/elsewhere && cd /root/elsewhere
for b in /usr/bin/viscera-*; do
  n=$(basename "$b")
  "$b" --version > /dev/null || { echo "FAIL: $n --version"; exit 1; }
  ls /usr/share/man/man1/"$n".1* > /dev/null 2>&1 || { echo "FAIL: no man page of $n under /usr/share/man/man1"; exit 1; }
  [ -f /usr/share/bash-completion/completions/"$n" ] || { echo "FAIL: no bash completion of $n"; exit 1; }
done
# Nobody on this partition: the client's "nothing seen" names the configuration it uses.
viscera-control --partition debcheck/nobody --wait 6 pause > control.log 2>&1
viscera-server --scene kidney_xpbd.yaml --partition debcheck/seat01 --duration 14 > server.log 2>&1 &
srv=$!
viscera-recorder --partition debcheck/seat01 --out session.db --duration 13 --quiet > recorder.log 2>&1 &
rec=$!
viscera-haptic --partition debcheck/seat01 --trajectory palpate_kidney.traj --quiet > haptic.log 2>&1
hap=$?
wait $srv; s=$?
wait $rec; r=$?
echo "exit: haptic $hap server $s recorder $r"
viscera-recinfo session.db > recinfo.log 2>&1
viscera-report --out report session.db > report.log 2>&1
echo "exit: report $?"
EOF
# A network namespace of its own (only lo, up): the session's DDS traffic
# meets no other process on this machine, whatever its domain.
unshare --net sh -c 'ip link set lo up && exec "$@"' sh \
  env -i HOME=/root PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 ${DOMAIN:+VISCERA_DOMAIN=$DOMAIN} \
  chroot "$R" bash /root/session.sh > "$WORK/session.log" 2>&1 || true
E="$R/root/elsewhere"
show() { for f in "$WORK/session.log" "$E"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -8 "$f"; }; done >&2; }
grep -q "^FAIL" "$WORK/session.log" && { show; fail "$(grep -m1 ^FAIL "$WORK/session.log")"; }
grep -q "exit: haptic 0 server 0 recorder 0" "$WORK/session.log" || { show; fail "a process of the session failed"; }
grep -q "scene kidney_xpbd.yaml found as /usr/.*share/viscera/assets/scenes/kidney_xpbd.yaml" "$E/server.log" ||
  { show; fail "the server did not take the installed scene"; }
grep -q "configuration: file:///usr/.*share/viscera/deploy/cyclonedds-loopback.xml" "$E/control.log" ||
  { show; fail "a client without CYCLONEDDS_URI does not name the installed loopback configuration"; }
peak=$(sed -n 's/.*peak_force=\([0-9.]*\).*/\1/p' "$E/haptic.log" | head -1)
echo "trainee peak force: ${peak:-none} N"
awk -v p="${peak:-0}" 'BEGIN { exit !(p > 0.5) }' || { show; fail "the trainee did not press the kidney (peak ${peak:-none} N)"; }
echo "recording: $(tail -1 "$E/recinfo.log")"
grep -q "exit: report 0" "$WORK/session.log" || { show; fail "viscera-report failed"; }
[ -s "$E/report/report.html" ] && [ -s "$E/report/report.csv" ] || { show; fail "the report was not written"; }
echo "report: $(du -k "$E/report/report.html" | cut -f1) kB HTML, $(wc -l < "$E/report/report.csv") CSV lines"

# 5. The postinst's user, with systemd present (Suggests).
if [ "$SYSTEMD" = 1 ]; then
  step "apt-get install systemd, reinstall the .deb (postinst: systemd-sysusers)"
  in_root apt-get install -y --no-install-recommends systemd > "$WORK/apt-systemd.log" 2>&1 ||
    { tail -20 "$WORK/apt-systemd.log"; fail "apt-get install systemd failed"; }
  grep -E "^(Need to get|After this operation)" "$WORK/apt-systemd.log" || true
  cp -n "$R"/var/cache/apt/archives/*.deb "$CACHE/archives/" 2> /dev/null || true
  # Not made by systemd's own postinst: then the user below is the postinst's.
  if in_root getent passwd viscera > /dev/null; then fail "a viscera user exists before the postinst ran with systemd"; fi
  in_root sh -c "cd /root && apt-get install -y --reinstall ./$(basename "$DEB")" > "$WORK/apt-reinstall.log" 2>&1 ||
    { tail -20 "$WORK/apt-reinstall.log"; fail "reinstalling the .deb with systemd present failed"; }
  in_root getent passwd viscera > "$WORK/user.txt" || fail "postinst did not create the viscera user (systemd-sysusers)"
  echo "user: $(cat "$WORK/user.txt")"
fi

# 6. Removal.
step "apt-get remove -y viscera"
in_root apt-get remove -y viscera > "$WORK/apt-remove.log" 2>&1 || { tail "$WORK/apt-remove.log"; fail "apt-get remove failed"; }
left=$(cd "$R" && ls -d usr/bin/viscera-* usr/share/viscera usr/lib/systemd/system/viscera-* 2> /dev/null || true)
[ -z "$left" ] || fail "left after apt-get remove: $left"
if in_root dpkg -s viscera 2> /dev/null | grep -q "^Status: install ok installed"; then fail "still installed after remove"; fi
step "PASS"
