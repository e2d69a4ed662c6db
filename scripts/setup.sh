#!/usr/bin/env bash
# Install what plugnproduce needs on a fresh Debian machine with Python 3.11:
# a Java runtime for HermiT, Graphviz for chart pictures, Chromium for the HMI's
# browser tests (driven by Playwright over its DevTools protocol: no separate driver),
# iproute2 ('ip') for the tests that put devices and controller in network namespaces,
# and the Python package with its test extras and what opening the notebooks needs.
# Says what it is doing, one line per phase, on stderr.
set -euo pipefail
cd "$(dirname "$0")/.."

say() { echo "setup: $*" >&2; }

say "checking system packages (Java runtime, Graphviz, Chromium, iproute2 for the network tests)"
need=()
command -v java >/dev/null 2>&1 || need+=(default-jre-headless)
command -v dot >/dev/null 2>&1 || need+=(graphviz)
command -v chromium >/dev/null 2>&1 || need+=(chromium)
# 'ip' (netns, veth): the tests that run the devices and the controller in network namespaces of their own
command -v ip >/dev/null 2>&1 || [ -x /usr/sbin/ip ] || [ -x /sbin/ip ] || need+=(iproute2)
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ]; then
        say "updating the package lists (apt-get update)"
        apt-get update -qq
        say "installing ${need[*]} (apt-get; a few minutes on a fresh machine)"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
    else
        say "please install ${need[*]} (needs root)"
        exit 1
    fi
else
    say "system packages already there"
fi

say "installing the Python package with its test and notebook extras (pip, the tested versions)"
python -m pip install --quiet --disable-pip-version-check -c scripts/constraints.txt -e ".[test,notebooks]"

say "done: try 'pnp capabilities --cell descriptions/cells/bin-picking.yaml'," \
    "'pnp run descriptions/tasks/bin-picking.yaml --sim' or 'jupyter lab notebooks/'"
