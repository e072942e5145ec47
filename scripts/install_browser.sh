#!/usr/bin/env bash
# Install Debian's headless Chromium and its driver for the browser tests, if missing.
# Fails loudly (exit 1) when they are missing and cannot be installed.
set -euo pipefail
if [ -x /usr/bin/chromium ] && [ -x /usr/bin/chromedriver ]; then
    exit 0
fi
echo "install_browser: installing Debian packages chromium and chromium-driver" >&2
if [ "$(id -u)" -eq 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo -n"; else
    echo "install_browser: chromium is missing and I am not root (no sudo): cannot install it" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q >&2
$SUDO apt-get install -y -q --no-install-recommends chromium chromium-driver >&2
if ! [ -x /usr/bin/chromium ] || ! [ -x /usr/bin/chromedriver ]; then
    echo "install_browser: /usr/bin/chromium or /usr/bin/chromedriver still missing after apt-get" >&2
    exit 1
fi
