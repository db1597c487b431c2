#!/usr/bin/env bash
# Installs every Debian 12 package the project needs. Idempotent and non-interactive:
# packages already present are skipped, so a warm machine pays only a dpkg query.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake ninja-build pkg-config g++ git
  # tests and benchmarks (openssl: the HTTPS gateway test makes a self-signed certificate)
  libgtest-dev libgmock-dev libbenchmark-dev openssl
  # fuzzing (tests/fuzz): clang with libFuzzer and the ASan/UBSan runtimes
  clang libclang-rt-14-dev
  # numerics: Eigen, CHOLMOD (SuiteSparse) with OpenBLAS behind it, nanoflann (kd-tree), CGAL (remeshing, AABB)
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libnanoflann-dev libcgal-dev
  # MUMPS (sequential): the multifrontal LDL^T of indefinite stiffness matrices (past pressure maxima)
  libmumps-seq-dev
  # mesh files (nlohmann-json: the glTF layout check before assimp reads an upload)
  libassimp-dev nlohmann-json3-dev
  # service: gRPC, protobuf, SQLite, HTTP gateway
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler libsqlite3-dev libcpp-httplib-dev
  # HTTPS for the gateway (--http-tls-cert): Debian's cpp-httplib is built with CPPHTTPLIB_OPENSSL_SUPPORT
  libssl-dev
  # cross-language client test
  python3-grpcio python3-protobuf
  # several shards behind a load balancer (tests/deploy): HAProxy (the test runs its own, unprivileged; the
  # system service Debian may start has no listeners in its default config); YAML for the Kubernetes check
  haproxy python3-yaml
  # browser test of the web page (tests/web): headless Chromium driven by playwright-core
  chromium
)

# The web page's build (client/web) and its browser test need node and npm. A machine that already has
# node (e.g. a newer one than Debian's) keeps it; only a machine without node gets Debian's nodejs and npm.
if ! command -v node >/dev/null 2>&1; then
  PACKAGES+=(nodejs npm)
elif ! command -v npm >/dev/null 2>&1; then
  echo "install-deps: node is installed but npm is not; install npm for the web page (client/web)" >&2
fi

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
