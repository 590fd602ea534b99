#!/usr/bin/env bash
# Installs vimot's build and run dependencies from Debian packages.
# Idempotent: packages already present are skipped, and apt is not touched
# at all when nothing is missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config ccache
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev   # LCM (pkg-config needs glib)
  libeigen3-dev libopencv-dev libceres-dev libserialport-dev catch2
  libyaml-cpp-dev                                    # configuration files
  default-jdk-headless libjchart2d-java              # lcm-gen --java, lcm-spy plots
  python3 python3-numpy python3-matplotlib           # plotting scripts
  clang libclang-rt-14-dev llvm                      # scripts/fuzz.sh: libFuzzer, llvm-cov (build option VIMOT_FUZZ)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
