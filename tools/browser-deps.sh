#!/usr/bin/env bash
# Install Debian's chromium for the live view's browser test (tests/view), when missing and root.
set -euo pipefail
command -v chromium >/dev/null 2>&1 && exit 0
if [ "$(id -u)" -ne 0 ]; then
    echo "browser-deps: chromium missing; not root, so not installing (the browser test skips)" >&2
    exit 0
fi
echo "browser-deps: installing chromium" >&2
export DEBIAN_FRONTEND=noninteractive
# another apt run (system-deps.sh, a colleague) may hold the lock for a while
apt-get -o DPkg::Lock::Timeout=300 update -qq
apt-get -o DPkg::Lock::Timeout=300 install -y -qq --no-install-recommends chromium fonts-dejavu-core >/dev/null
