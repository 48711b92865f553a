#!/usr/bin/env bash
# Everything `npm test` runs: installs what the tests need (Chromium from apt if
# absent, the Rust target, wasm-bindgen, node_modules), builds, then runs the Rust
# tests, the TypeScript type check, and the node + browser tests. Every suite runs
# even when an earlier one fails; the exit status is non-zero if any failed.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
[ -d "$HOME/.cargo/bin" ] && export PATH="$HOME/.cargo/bin:$PATH"

find_chromium() {
  local c
  for c in "${CHROMIUM_PATH:-}" /usr/bin/chromium /usr/bin/chromium-browser; do
    if [ -n "$c" ] && [ -x "$c" ]; then echo "$c"; return 0; fi
  done
  return 1
}

if ! chromium=$(find_chromium); then
  echo "test: no Chromium found; installing the Debian package"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y chromium
  chromium=$(find_chromium) || { echo "test: Chromium still not found after apt-get install" >&2; exit 1; }
fi
export CHROMIUM_PATH="$chromium"

bash scripts/setup.sh
node scripts/build.mjs

failed=()
step() {
  local name=$1; shift
  echo
  echo "==> $name: $*"
  local t0=$SECONDS
  if "$@"; then
    echo "==> $name: ok ($((SECONDS - t0)) s)"
  else
    echo "==> $name: FAILED ($((SECONDS - t0)) s)"
    failed+=("$name")
  fi
}

step rust cargo test --workspace
step typecheck npx tsc --noEmit -p .
step node node --test --test-concurrency=1 tests/node/ tests/e2e/

echo
if [ ${#failed[@]} -gt 0 ]; then
  echo "test: FAILED: ${failed[*]}"
  exit 1
fi
echo "test: all passed (screenshots in tests/output/)"
