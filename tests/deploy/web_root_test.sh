#!/bin/sh
# balloon-server copied into a fresh prefix (as `cmake --install` does) looks for its page in that prefix's
# share/balloon/web, and the binary carries no build-tree web root.
# Usage: web_root_test.sh BALLOON_SERVER BUILD_DIR
set -eu
server=$1
build_dir=$2
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
mkdir -p "$prefix/bin"
cp "$server" "$prefix/bin/balloon-server"
line=$("$prefix/bin/balloon-server" --help | grep -e '--web-root DIR')
case "$line" in
  *"[$prefix/share/balloon/web]"*) ;;
  *) echo "the installed default --web-root is not $prefix/share/balloon/web: $line"; exit 1 ;;
esac
if grep -qaF "$build_dir/client/web/dist" "$server"; then
  echo "balloon-server has the build-tree web root $build_dir/client/web/dist compiled in"
  exit 1
fi
echo "default --web-root follows the executable: $line"
