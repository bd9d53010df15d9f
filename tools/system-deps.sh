#!/usr/bin/env bash
# Install the Debian packages the firmware build and tests need, when missing and run as root.
set -euo pipefail
packages=(gcc make gcc-avr avr-libc binutils-avr simavr libsimavr-dev avrdude
          arduino-core-avr # the Uno's bootloader (optiboot) for the simulated Uno
          clang            # libFuzzer with ASan and UBSan (tools/fuzz.py) ...
          libclang-rt-dev) # ... and their runtimes, which clang only recommends
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
    echo "system-deps: missing ${missing[*]}; not root, so not installing (tests that need them skip)" >&2
    exit 0
fi
echo "system-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
