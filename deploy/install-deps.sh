#!/usr/bin/env bash
# Installs every Debian 12 package the project needs. Idempotent and non-interactive:
# packages already present are skipped, so a warm machine pays only a dpkg query.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake ninja-build pkg-config g++ git
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # numerics: Eigen, CHOLMOD (SuiteSparse) with OpenBLAS behind it, nanoflann (kd-tree), CGAL (remeshing, AABB)
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libnanoflann-dev libcgal-dev
  # mesh files
  libassimp-dev
  # service: gRPC, protobuf, SQLite, HTTP gateway
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler libsqlite3-dev libcpp-httplib-dev
  # cross-language client test
  python3-grpcio python3-protobuf
)

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -q
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
