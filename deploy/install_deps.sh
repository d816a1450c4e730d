#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs, with apt-get, exactly the Debian 12 packages viscera needs that are
# missing. Idempotent and non-interactive; run as root (or with sudo present).
set -euo pipefail

PKGS=(
  build-essential cmake pkg-config          # toolchain
  cyclonedds-dev cyclonedds-tools           # DDS library, headers, idlc
  libosmesa6-dev                            # offscreen OpenGL for the viewer
  libassimp-dev                             # mesh import
  libpng-dev                                # PNG frames
  libsqlite3-dev sqlite3                    # recordings
  zlib1g-dev                                # keyframe chunks: deflate (common/dds/key_chunks.c)
  libyaml-dev                               # scene files
  libcairo2-dev                             # plots in benchmarks and reports
  openssl                                   # DDS Security PKI (deploy/pki.sh)
  libssl-dev                                # certificate subjects in recordings (common/dds/vdds_subject.c)
  libsdl2-dev                               # window viewer (--window, --drive)
  xvfb xauth                                # headless X server for the window test
  systemd                                   # systemd-analyze verify of the service units (test)
  help2man                                  # man pages generated at build time from --help
  dpkg-dev file                             # dpkg-shlibdeps and file: the .deb's computed Depends (cpack)
  iproute2 ethtool                          # network tests: namespaces, veths, checksum offload off
)

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PKGS[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then SUDO=sudo; else
    echo "install_deps: missing packages (${missing[*]}) and not root; run as root" >&2
    exit 1
  fi
fi
echo "install_deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install_deps: done"
