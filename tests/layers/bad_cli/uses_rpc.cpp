// Fixture: the CLI reaching into the service through the rpc layer.
#include "rpc/grpc_server.hpp"
#include "embedded/embedded_server.hpp"
