#!/usr/bin/env bash
# Configures, builds (Release) and runs every test. This is the README's test command.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" -j"$(nproc)"
# A test that fails is run once more before the run fails (--repeat until-pass:2): the service tests run
# real servers side by side on 2 cores, and one load-sensitive failure should not hide the rest. Every
# retry is printed in ctest's output, so a flaky test stays visible.
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" --timeout 900 --repeat until-pass:2

# The libFuzzer targets (issue 11), all seven, 30 s each: a separate clang build of the readers (build-fuzz)
# with ASan and UBSan; any crash, leak or input over 1 s fails the run. Each replays seed 1 up to the
# 20,000-run cap, a prefix of runs checked clean beforehand (tests/fuzz/README.md).
tests/fuzz/run_fuzzers.sh "${FUZZ_SECONDS:-30}"

# The web page (issue 6): unit tests of its modules, then the browser test: balloon-server --http with
# the built page, driven in headless Debian Chromium by playwright-core. npm ci runs only when
# tests/web/package-lock.json changed.
web_stamp="$BUILD_DIR/tests/web/npm-ci.stamp"
if [[ ! -f "$web_stamp" || ! -d tests/web/node_modules || tests/web/package-lock.json -nt "$web_stamp" ]]; then
  (cd tests/web && npm ci --no-audit --no-fund --loglevel=error)
  mkdir -p "$(dirname "$web_stamp")"
  touch "$web_stamp"
fi
node --test --test-reporter=spec tests/web/page_modules_test.mjs
node tests/web/browser_test.mjs --server "$BUILD_DIR/server/balloon-server" \
  --web-root "$BUILD_DIR/client/web/dist" --artifacts "$BUILD_DIR/test-artifacts/web"
