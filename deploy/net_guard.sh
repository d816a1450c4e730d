# SPDX-License-Identifier: Apache-2.0
# shellcheck shell=bash
# Off loopback, secure by default (issue 14): sourced by the deploy scripts
# that start processes with a CYCLONEDDS_URI (lab.sh, session.sh,
# load_bench.sh).
#
# net_guard SCRIPT URI SECURE INSECURE [HOW]: returns 0 when URI may be used: it is
# the loopback configuration (deploy/cyclonedds-loopback.xml: nothing leaves
# the machine), or it names a DDS Security fragment (pki.sh's
# identities/NAME/security.xml), or SECURE=1 (the script adds an identity per
# process). Otherwise, with INSECURE=1, it prints a warning, exports
# VISCERA_INSECURE=1 (every program the script starts would refuse the
# configuration without it: common/dds/vdds_config.h) and returns 0;
# without, it prints how to proceed (HOW, default: lab.sh's --secure and
# --insecure) and returns 2.
net_guard() {
  local script="$1" uri="$2" secure="$3" insecure="$4"
  local how="${5:-run with --secure (DDS Security, PKI from deploy/pki.sh), or with --insecure to run without it}"
  case "$uri" in
    file://*/cyclonedds-loopback.xml) return 0 ;;
  esac
  [[ "$uri" == *security.xml* || "$uri" == *"<Security"* || "$uri" == *"<DDSSecurity"* ]] && return 0
  [ "$secure" = 1 ] && return 0
  if [ "$insecure" != 1 ]; then
    echo "$script: CYCLONEDDS_URI=$uri is not the loopback configuration: $how" >&2
    return 2
  fi
  echo "$script: WARNING: insecure: DDS Security is off on $uri; anyone on that network can read" \
    "every seat and drive its tools" >&2
  export VISCERA_INSECURE=1
  return 0
}
