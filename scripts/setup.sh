#!/usr/bin/env bash
# Installs cvslam's Debian packages and prepares this host for LCM over loopback multicast
# (docs/architecture.md). Idempotent and quick when everything is in place.
#
#   scripts/setup.sh            install what is missing, configure multicast (as root)
#   scripts/setup.sh --check    only report what is missing; exit 1 if anything is
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  liblcm-dev liblcm-bin liblcm-java default-jdk-headless libjchart2d-java
  clang libeigen3-dev libopencv-dev libceres-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libboost-math-dev clang-tidy
  python3-matplotlib python3-numpy
  iproute2 procps xvfb
  libcpp-httplib-dev libssl-dev chromium chromium-driver nftables
  libnetfilter-queue-dev iptables
)

check_only=false
case "${1:-}" in
  --check) check_only=true ;;
  -h|--help)
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
    exit 0 ;;
  "") ;;
  *) echo "setup.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else echo "  (needs root) $*"; return 1; fi
}

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: missing Debian packages: ${missing[*]}"
  if $check_only; then exit 1; fi
  if [ "$(id -u)" -ne 0 ]; then
    echo "setup: run as root, or: sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "setup: installed ${#missing[@]} package(s)"
else
  echo "setup: all Debian packages present"
fi

# The script tests run the Python tools with /usr/bin/python3 (tests/tools/python_modules.sh;
# a python3 earlier on PATH, e.g. pyenv's, may lack the Debian modules).
if ! /usr/bin/python3 -c 'import numpy, matplotlib' 2>/dev/null; then
  echo "setup: /usr/bin/python3 cannot import numpy and matplotlib (python3-numpy, python3-matplotlib)" >&2
  $check_only && exit 1
fi

# --- loopback multicast for LCM (udpm://239.255.76.67:7667?ttl=0 never leaves the host) ---
net_ok=true
if ! ip link show lo 2>/dev/null | grep -q MULTICAST; then
  echo "setup: enabling multicast on lo"
  $check_only || as_root ip link set lo multicast on || net_ok=false
fi
if ! ip route show 239.0.0.0/8 2>/dev/null | grep -q "dev lo"; then
  echo "setup: routing 239.0.0.0/8 via lo"
  $check_only || as_root ip route add 239.0.0.0/8 dev lo 2>/dev/null ||
    as_root ip route replace 239.0.0.0/8 dev lo || net_ok=false
fi
# Stereo images are large datagrams: raise the socket receive buffers (docs/architecture.md).
want_rmem=16777216
for key in net.core.rmem_max net.core.rmem_default; do
  cur=$(sysctl -n "$key" 2>/dev/null || echo 0)
  if [ "$cur" -lt "$want_rmem" ]; then
    echo "setup: raising $key from $cur to $want_rmem"
    $check_only || as_root sysctl -q -w "$key=$want_rmem" || net_ok=false
  fi
done
if ! $net_ok; then
  echo "setup: multicast/buffer setup incomplete; run the commands above as root" >&2
fi
echo "setup: done"
