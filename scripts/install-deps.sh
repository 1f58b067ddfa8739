#!/usr/bin/env bash
# Installs the Debian bookworm packages gyrod builds and tests with (see README,
# "Dependencies"). Does nothing when all are present; needs root otherwise.
set -euo pipefail
packages=(
  g++ cmake make ninja-build pkg-config
  libeigen3-dev libboost-math-dev nlohmann-json3-dev libcli11-dev libtomlplusplus-dev
  libspdlog-dev libi2c-dev libgpiod-dev libsystemd-dev libmosquitto-dev mosquitto openssl
  libgtest-dev libbenchmark-dev zlib1g-dev
  gnuplot-nox systemd python3
  python3-numpy python3-pandas
  clang-format clang-tidy
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: run as root (or: sudo apt-get install ${missing[*]})" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
