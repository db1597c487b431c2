#pragma once
/// Listen addresses and host names, parsed once for every check that asks "does this only reach this
/// machine?" (the gRPC --listen rule, the HTTP --http rule, the gateway's Host and Origin checks).
#include <string>
#include <string_view>
#include <utility>

#include "result.hpp"

namespace balloon::net {

/// Splits "HOST:PORT" / "[V6]:PORT" into host (brackets removed) and port 0..65535; fails naming the
/// problem, with `what` ("HTTP address") leading the message.
Result<std::pair<std::string, int>> split_host_port(const std::string& address, const std::string& what = "address");

/// True when `host` (no brackets, no port) names this machine's loopback interface: "localhost" (any case),
/// an IPv4 address in 127.0.0.0/8 written as a dotted quad, "::1" or an IPv4-mapped loopback
/// ("::ffff:127.0.0.1"). The text is parsed as an address: "127.evil.example" is a DNS name, not loopback.
bool is_loopback_host(std::string_view host);

/// True when a listen address ("host:port", "[v6]:port", "unix:path", "unix-abstract:name") only reaches
/// this machine. Anything that does not parse is treated as reachable from outside.
bool is_loopback_address(const std::string& address);

}  // namespace balloon::net
