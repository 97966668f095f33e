#!/bin/sh
# Installs every Debian 12 package partray needs. Idempotent: runs
# `apt-get update` at most once per machine (a stamp in /var/lib/partray) and
# installs nothing when everything is already there.
set -eu
PKGS="build-essential cmake pkg-config
libembree-dev libopenexr-dev libopencolorio-dev libpng-dev
ocl-icd-opencl-dev opencl-headers pocl-opencl-icd
libcmocka-dev libsdl2-dev libfreetype-dev libjpeg-dev libtiff-dev libgif-dev
povray povray-includes povray-examples
xvfb clang libclang-rt-14-dev valgrind
slurmctld slurmd slurm-client munge parallel openssh-server openssh-client"

missing=""
for p in $PKGS; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
if [ -z "$missing" ]; then
    echo "setup: all packages present"
    exit 0
fi
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
STAMP=/var/lib/partray/apt-updated
if [ ! -f "$STAMP" ]; then
    $SUDO apt-get update
    $SUDO mkdir -p /var/lib/partray && $SUDO touch "$STAMP"
fi
echo "setup: installing$missing"
# shellcheck disable=SC2086
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends $missing
