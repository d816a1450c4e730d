#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# deb_check (issue 18 item 3): deploy/deb_check.sh builds the .deb from this
# build tree, apt-installs it on a clean Debian 12 (debootstrap minbase) and
# runs a session from the installed files. A first run downloads about
# 100+ MB from the Debian mirror, so it runs only with VISCERA_DEB_CHECK=1
# (and as root); otherwise it is skipped (77). The debootstrap root and apt's
# downloads are cached in $VISCERA_DEB_CHECK_CACHE (default
# /var/cache/viscera-debcheck).
# usage: deb_check_test.sh BUILD SRC OUT
set -euo pipefail
BUILD="$1"; SRC="$2"
[ "${VISCERA_DEB_CHECK:-0}" = 1 ] || { echo "SKIP: set VISCERA_DEB_CHECK=1 (downloads ~100+ MB on a first run)"; exit 77; }
exec bash "$SRC/deploy/deb_check.sh" --build "$BUILD" --cache "${VISCERA_DEB_CHECK_CACHE:-/var/cache/viscera-debcheck}"
