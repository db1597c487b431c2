#pragma once
// Fixture: a core header that reaches gRPC.
#include <grpcpp/grpcpp.h>
