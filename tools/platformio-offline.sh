#!/usr/bin/env bash
# Install PlatformIO Core into .venv and assemble its atmelavr platform offline, from Debian and PyPI.
#
#   bash tools/platformio-offline.sh        then: PLATFORMIO_CORE_DIR=build/platformio .venv/bin/pio run
#
# PlatformIO Core (pinned) comes from PyPI. The "atmelavr" platform is the snapshot in
# ../shared/platformio/platform-atmelavr, installed by symlink under its own name, so
# platformio.ini's `platform = atmelavr` is unchanged. The packages it asks for are assembled from
# Debian's avr-gcc/binutils-avr/avr-libc and avrdude and from PyPI's SCons, each with the
# package.json and .piopm that PlatformIO accepts as an installed registry package. Everything
# lands in PLATFORMIO_CORE_DIR (default build/platformio, ignored by git): nothing goes to the
# user's home and nothing comes from PlatformIO's registry. On a machine that reaches the registry,
# leave PLATFORMIO_CORE_DIR unset and `pio run` fetches the stock packages for the same platformio.ini.
#
# Exit status: 0 ready; 3 the platform snapshot or Debian's AVR tools are absent (the tests skip,
# saying so); 1 anything else.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
VENV=${VENV:-$ROOT/.venv}
CORE=${PLATFORMIO_CORE_DIR:-$ROOT/build/platformio}
PLATFORM=${PLATFORMIO_PLATFORM:-$(dirname "$ROOT")/shared/platformio/platform-atmelavr}

PLATFORMIO_VERSION=6.2.0 # PlatformIO Core, from PyPI
SCONS_VERSION=4.11.1     # SCons from PyPI; PlatformIO 6.2.0 wants tool-scons ~4.41101.0
# versions that meet platform-atmelavr 5.2.0's requirements; the real contents are Debian's
TOOLCHAIN_VERSION=1.70300.0+debian # toolchain-atmelavr ~1.70300.0 (Debian's avr-gcc inside)
AVRDUDE_VERSION=1.60300.0+debian   # tool-avrdude ~1.60300.0 (Debian's avrdude inside)
SCONS_PACKAGE_VERSION=4.41101.0

say() { echo "platformio-offline: $*" >&2; }

if [ ! -f "$PLATFORM/platform.json" ]; then
    say "no platform snapshot at $PLATFORM (shared/platformio beside the repository)"
    exit 3
fi
for tool in avr-gcc avr-objcopy avr-size avrdude; do
    command -v "$tool" >/dev/null || { say "$tool not found: run make system-deps as root"; exit 3; }
done
[ -x "$VENV/bin/python" ] || { say "no virtual environment at $VENV: run make venv"; exit 1; }

pip() { "$VENV/bin/pip" install --quiet --disable-pip-version-check "$@"; }
if [ "$("$VENV/bin/python" -c 'import platformio; print(platformio.__version__)' 2>/dev/null)" \
     != "$PLATFORMIO_VERSION" ]; then
    say "installing PlatformIO Core $PLATFORMIO_VERSION into $VENV"
    pip "platformio==$PLATFORMIO_VERSION"
fi

packages=$CORE/packages
mkdir -p "$packages"

# package NAME VERSION TYPE DESCRIPTION: the two files that make a folder an installed package
package() {
    local dir=$packages/$1
    mkdir -p "$dir"
    printf '{"name": "%s", "version": "%s", "description": "%s"}\n' "$1" "$2" "$4" \
        >"$dir/package.json"
    printf '{"type": "%s", "name": "%s", "version": "%s", "spec": {"owner": "platformio", "id": null, "name": "%s", "requirements": null, "uri": null}}\n' \
        "$3" "$1" "$2" "$1" >"$dir/.piopm"
}

# toolchain-atmelavr: bin/ links Debian's AVR tools (avr-libc is found by avr-gcc itself)
gcc_version=$(avr-gcc -dumpversion)
package toolchain-atmelavr "$TOOLCHAIN_VERSION" tool "Debian's avr-gcc $gcc_version, binutils-avr and avr-libc"
mkdir -p "$packages/toolchain-atmelavr/bin"
for tool in /usr/bin/avr-*; do
    ln -sfn "$tool" "$packages/toolchain-atmelavr/bin/$(basename "$tool")"
done

# tool-avrdude: Debian's avrdude and a copy of its configuration (the platform passes -C)
package tool-avrdude "$AVRDUDE_VERSION" uploader "Debian's avrdude $(avrdude -? 2>&1 | grep -o 'version [0-9.]*' | head -1 | cut -d' ' -f2 || true)"
ln -sfn "$(command -v avrdude)" "$packages/tool-avrdude/avrdude"
cp /etc/avrdude.conf "$packages/tool-avrdude/avrdude.conf"

# tool-scons: SCons from PyPI, run by the scons.py PlatformIO calls with its own Python
scons=$packages/tool-scons
if [ "$(cat "$scons/.scons-version" 2>/dev/null)" != "$SCONS_VERSION" ]; then
    say "installing SCons $SCONS_VERSION into $scons"
    rm -rf "$scons/lib"
    pip --target "$scons/lib" "scons==$SCONS_VERSION"
    echo "$SCONS_VERSION" >"$scons/.scons-version"
fi
package tool-scons "$SCONS_PACKAGE_VERSION" tool "SCons $SCONS_VERSION from PyPI"
cat >"$scons/scons.py" <<'EOF'
"""Run SCons from the copy beside this file (the entry point PlatformIO calls)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
from SCons.Script.Main import main  # noqa: E402

main()
EOF

# the platform, by symlink under its own name
export PLATFORMIO_CORE_DIR=$CORE
if ! grep -qsF "$PLATFORM" "$CORE"/platforms/*.pio-link; then
    say "installing the atmelavr platform from $PLATFORM"
    "$VENV/bin/pio" pkg install --global --skip-dependencies \
        --platform "symlink://$PLATFORM" >/dev/null
fi
say "ready: PLATFORMIO_CORE_DIR=$CORE $VENV/bin/pio run"
