#!/usr/bin/env bash
# Install what plugnproduce needs on a fresh Debian machine with Python 3.11:
# a Java runtime for HermiT, Graphviz for chart pictures, Chromium and its driver
# for the HMI's browser tests, and the Python package with its test extras.
set -euo pipefail
cd "$(dirname "$0")/.."

need=()
command -v java >/dev/null 2>&1 || need+=(default-jre-headless)
command -v dot >/dev/null 2>&1 || need+=(graphviz)
command -v chromium >/dev/null 2>&1 || need+=(chromium chromium-driver)
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ]; then
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
    else
        echo "setup: please install ${need[*]} (needs root)" >&2
        exit 1
    fi
fi

python -m pip install --quiet --disable-pip-version-check -e ".[test]"
