#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Generates everything DDS Security needs for a viscera lab: two certificate
# authorities (identity, permissions), one certificate per participant
# identity, and the signed governance and permissions documents that enforce
# the roles per seat partition. Also writes, per identity, the Cyclone DDS
# configuration fragment that turns security on for a process using it.
#
# Usage: deploy/pki.sh OUT_DIR [--seats N] [--prefix lab] [--days D] [--org NAME]
#                      [--server-group K-M ...]
#
# Identities (one per process: Cyclone applies security per process):
#   server-seatNN   publishes the seat's scene state, reads its commands
#   server-seatKK-MM  (--server-group K-M, repeatable) the same for seats K..M
#                   at once: one viscera-server --seats M-K+1 --first-seat K
#                   process, whose seats share its identity (they share its
#                   memory anyway; lab.sh --one-server --secure)
#   trainee-seatNN  publishes ToolCommand in its own seat only
#   instructor      publishes SessionControl and ToolCommand (take-over) in every seat
#   observer        reads every seat, publishes nothing
#   recorder        reads every seat, publishes nothing
# Partitions are PREFIX/seatNN (viscera-server --partition lab/seat03).
# A process uses an identity with
#   CYCLONEDDS_URI="file://<network config>,file://OUT_DIR/identities/NAME/security.xml"
# The private keys are not encrypted: keep OUT_DIR readable only by the lab
# account (the script makes it 0700). Needs openssl only.
# Run again on the same OUT_DIR (more seats, another --server-group), it keeps
# the two CAs it finds there and signs everything anew with them: identities
# already handed out, running processes and copies of the PKI on other
# machines stay valid. Remove OUT_DIR to start from new CAs.
set -euo pipefail

usage() { awk 'NR > 2 && /^#/ { sub(/^# ?/, ""); print; next } NR > 2 { exit }' "$0"; } # the header
[ $# -ge 1 ] || { usage >&2; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
OUT="$1"; shift
SEATS=2 PREFIX=lab DAYS=3650 ORG=viscera GROUPS_=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seats) SEATS="$2"; shift 2 ;;
    --prefix) PREFIX="$2"; shift 2 ;;
    --days) DAYS="$2"; shift 2 ;;
    --org) ORG="$2"; shift 2 ;;
    --server-group) GROUPS_+=("$2"); shift 2 ;;
    *) echo "pki.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
  esac
done
[[ "$SEATS" =~ ^[0-9]+$ ]] && [ "$SEATS" -ge 1 ] && [ "$SEATS" -le 99 ] || { echo "pki.sh: --seats must be 1..99" >&2; exit 2; }
[[ "$PREFIX" =~ ^[A-Za-z0-9_-]+$ ]] || { echo "pki.sh: --prefix: letters, digits, '-' and '_' only" >&2; exit 2; }
for g in "${GROUPS_[@]}"; do
  [[ "$g" =~ ^([0-9]{1,2})-([0-9]{1,2})$ ]] && [ "$((10#${BASH_REMATCH[1]}))" -ge 1 ] &&
    [ "$((10#${BASH_REMATCH[1]}))" -lt "$((10#${BASH_REMATCH[2]}))" ] && [ "$((10#${BASH_REMATCH[2]}))" -le "$SEATS" ] ||
    { echo "pki.sh: --server-group '$g': K-M with 1 <= K < M <= --seats ($SEATS)" >&2; exit 2; }
done
[[ "$ORG" =~ ^[A-Za-z0-9_-]+$ ]] || { echo "pki.sh: --org: letters, digits, '-' and '_' only" >&2; exit 2; }
command -v openssl >/dev/null || { echo "pki.sh: openssl not found (bash deploy/install_deps.sh installs it)" >&2; exit 1; }

mkdir -p "$OUT"
chmod 700 "$OUT"
OUT="$(cd "$OUT" && pwd)"
CA="$OUT/ca"
mkdir -p "$CA" "$OUT/identities"

# EC P-256 keys: what the Cyclone authentication plugin supports besides RSA-2048, and cheap.
newkey() { openssl ecparam -name prime256v1 -genkey -noout -out "$1" 2>/dev/null; chmod 600 "$1"; }

make_ca() { # name file-stem
  # An existing CA is kept: a rerun (more seats, a --server-group that
  # lab.sh --one-server asks for) then signs with the same CAs, so the
  # certificates already handed out, running processes and copies of the
  # PKI on other machines stay valid. Remove OUT_DIR for new CAs.
  if [ -s "$CA/$2.pem" ] && [ -s "$CA/$2_key.pem" ]; then
    KEPT+=("$2")
    return 0
  fi
  newkey "$CA/$2_key.pem"
  openssl req -x509 -new -key "$CA/$2_key.pem" -days "$DAYS" -sha256 \
    -subj "/C=NL/O=$ORG/CN=$1" -out "$CA/$2.pem" 2>/dev/null
}
KEPT=()
make_ca "$ORG identity CA" identity_ca
make_ca "$ORG permissions CA" permissions_ca

NOW="$(date -u +%Y-%m-%dT%H:%M:%S)"
UNTIL="$(date -u -d "+$DAYS days" +%Y-%m-%dT%H:%M:%S)"
ALL_TOPICS='<topic>viscera_*</topic>'
STATE_TOPICS='<topic>viscera_SceneInfo</topic><topic>viscera_MeshState</topic><topic>viscera_MeshKeyChunk</topic><topic>viscera_MeshDelta</topic><topic>viscera_ContactFeedback</topic><topic>viscera_SessionEvent</topic><topic>viscera_Metrics</topic><topic>viscera_ObjectState</topic><topic>viscera_ToolMetrics</topic><topic>viscera_ToolRole</topic><topic>viscera_AppliedInput</topic><topic>viscera_SceneSource</topic>'
INPUT_TOPICS='<topic>viscera_ToolCommand</topic><topic>viscera_SessionControl</topic>'

# grant NAME PUB_TOPICS PUB_PARTITIONS SUB_TOPICS SUB_PARTITIONS (partitions: space-separated)
grant() {
  local pub="" p pubp="" subp="" pa sa
  read -ra pa <<< "$3" # read, not an unquoted $3: "lab/*" must not glob
  read -ra sa <<< "$5"
  for p in "${pa[@]}"; do pubp+="<partition>$p</partition>"; done
  for p in "${sa[@]}"; do subp+="<partition>$p</partition>"; done
  if [ -n "$2" ]; then
    pub="<publish><topics>$2</topics><partitions>$pubp</partitions></publish>"
  fi
  cat <<XML
    <grant name="$1">
      <subject_name>CN=$1,O=$ORG,C=NL</subject_name>
      <validity><not_before>$NOW</not_before><not_after>$UNTIL</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        $pub
        <subscribe><topics>$4</topics><partitions>$subp</partitions></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
XML
}

identities=(instructor observer recorder)
{
  echo '<?xml version="1.0" encoding="UTF-8"?>'
  echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
  echo '  <permissions>'
  grant instructor '<topic>viscera_SessionControl</topic><topic>viscera_ToolCommand</topic>' "$PREFIX/*" "$ALL_TOPICS" "$PREFIX/*"
  grant observer '' '' "$ALL_TOPICS" "$PREFIX/*"
  grant recorder '' '' "$ALL_TOPICS" "$PREFIX/*"
  for i in $(seq 1 "$SEATS"); do
    s=$(printf 'seat%02d' "$i")
    grant "server-$s" "$STATE_TOPICS" "$PREFIX/$s" "$INPUT_TOPICS" "$PREFIX/$s"
    # A trainee reads everything of its own seat (including the instructor's
    # SessionControl, so it knows when the seat is paused) and writes only its tool.
    grant "trainee-$s" '<topic>viscera_ToolCommand</topic>' "$PREFIX/$s" "$ALL_TOPICS" "$PREFIX/$s"
    identities+=("server-$s" "trainee-$s")
  done
  for g in "${GROUPS_[@]}"; do
    k=$((10#${g%-*})) m=$((10#${g#*-})) parts=""
    for i in $(seq "$k" "$m"); do parts+="$PREFIX/$(printf 'seat%02d' "$i") "; done
    name="$(printf 'server-seat%02d-%02d' "$k" "$m")"
    grant "$name" "$STATE_TOPICS" "$parts" "$INPUT_TOPICS" "$parts"
    identities+=("$name")
  done
  echo '  </permissions>'
  echo '</dds>'
} > "$OUT/permissions.xml"

# Governance: nobody joins unauthenticated; discovery, liveliness and every
# topic's data are encrypted, and read/write access control is on for every
# topic (the permissions above decide who may do what).
cat > "$OUT/governance.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>NONE</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML

sign() { openssl smime -sign -text -in "$OUT/$1.xml" -out "$OUT/$1.p7s" \
  -signer "$CA/permissions_ca.pem" -inkey "$CA/permissions_ca_key.pem" 2>/dev/null; }
sign governance
sign permissions

for name in "${identities[@]}"; do
  d="$OUT/identities/$name"
  mkdir -p "$d"
  newkey "$d/key.pem"
  openssl req -new -key "$d/key.pem" -subj "/C=NL/O=$ORG/CN=$name" -out "$d/req.csr" 2>/dev/null
  openssl x509 -req -in "$d/req.csr" -CA "$CA/identity_ca.pem" -CAkey "$CA/identity_ca_key.pem" \
    -CAcreateserial -days "$DAYS" -sha256 -out "$d/cert.pem" 2>/dev/null
  rm -f "$d/req.csr"
  cat > "$d/security.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<!-- DDS Security for identity '$name' (generated by deploy/pki.sh). Combine
     with a network configuration: CYCLONEDDS_URI="file://net.xml,file://this". -->
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <Security>
      <Authentication>
        <IdentityCertificate>file:$d/cert.pem</IdentityCertificate>
        <IdentityCA>file:$CA/identity_ca.pem</IdentityCA>
        <PrivateKey>file:$d/key.pem</PrivateKey>
      </Authentication>
      <AccessControl>
        <Governance>file:$OUT/governance.p7s</Governance>
        <PermissionsCA>file:$CA/permissions_ca.pem</PermissionsCA>
        <Permissions>file:$OUT/permissions.p7s</Permissions>
      </AccessControl>
    </Security>
  </Domain>
</CycloneDDS>
XML
done
rm -f "$CA"/*.srl
[ ${#KEPT[@]} = 0 ] || echo "pki.sh: $OUT: kept the existing CAs (${KEPT[*]}): earlier certificates stay valid"
echo "pki.sh: $OUT: ${#identities[@]} identities (${identities[*]}), partitions $PREFIX/seat01..$(printf 'seat%02d' "$SEATS")"
