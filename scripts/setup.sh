#!/usr/bin/env bash
# One-time tool setup; fast and quiet when everything is already in place.
#   - the wasm32-unknown-unknown Rust target
#   - wasm-bindgen CLI at exactly the version Cargo.lock pins
#   - node_modules from package-lock.json (npm ci), only when missing or stale
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
[ -d "$HOME/.cargo/bin" ] && export PATH="$HOME/.cargo/bin:$PATH"

need() { command -v "$1" >/dev/null 2>&1 || { echo "setup: '$1' not found on PATH; $2" >&2; exit 1; }; }
need cargo "install Rust with rustup (https://rustup.rs)"
need node "install Node.js 20 or newer"
need npm "install npm (ships with Node.js)"

if command -v rustup >/dev/null 2>&1; then
  if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    echo "setup: adding Rust target wasm32-unknown-unknown"
    rustup target add wasm32-unknown-unknown
  fi
fi

want=$(awk '$0 == "name = \"wasm-bindgen\"" { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$want" ]; then
  echo "setup: no wasm-bindgen entry in Cargo.lock" >&2
  exit 1
fi
have=$(wasm-bindgen --version 2>/dev/null | awk '{ print $2 }' || true)
if [ "$have" != "$want" ]; then
  echo "setup: installing wasm-bindgen-cli $want (found: ${have:-none})"
  cargo install --locked wasm-bindgen-cli --version "$want"
fi

# node_modules/.package-lock.json is npm's own record of the installed tree.
stamp=node_modules/.package-lock.json
if [ ! -f "$stamp" ] || [ package-lock.json -nt "$stamp" ]; then
  echo "setup: npm ci"
  npm ci --no-audit --no-fund
  touch "$stamp"
fi
