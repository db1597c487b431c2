#include "net/network_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cstdlib>

namespace balloon::net {

Result<std::pair<std::string, int>> split_host_port(const std::string& address, const std::string& what) {
  std::string host, port_text;
  if (!address.empty() && address.front() == '[') {
    const auto close = address.find(']');
    if (close == std::string::npos || close + 1 >= address.size() || address[close + 1] != ':')
      return fail(what + " '" + address + "' must read [V6ADDRESS]:PORT");
    host = address.substr(1, close - 1);
    port_text = address.substr(close + 2);
  } else {
    const auto colon = address.rfind(':');
    if (colon == std::string::npos || colon == 0) return fail(what + " '" + address + "' must read HOST:PORT");
    host = address.substr(0, colon);
    port_text = address.substr(colon + 1);
    if (host.find(':') != std::string::npos)
      return fail(what + " '" + address + "': write an IPv6 host in brackets, [V6ADDRESS]:PORT");
  }
  char* end = nullptr;
  const long port = std::strtol(port_text.c_str(), &end, 10);
  if (port_text.empty() || *end != '\0' || port < 0 || port > 65535 || port_text.size() > 5)
    return fail(what + " '" + address + "': port '" + port_text + "' is not a number in 0..65535");
  return std::make_pair(host, static_cast<int>(port));
}

bool is_loopback_host(std::string_view host) {
  if (host.size() == 9) {
    std::string lower(host);
    for (char& c : lower) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    if (lower == "localhost") return true;
  }
  if (host.size() > 64) return false;
  const std::string text(host);
  in_addr v4{};
  // inet_pton takes only the full dotted quad: no "127.1", no hex, no trailing text.
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, text.c_str(), &v6) == 1) {
    if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
    return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
  }
  return false;
}

bool is_loopback_address(const std::string& address) {
  if (address.rfind("unix:", 0) == 0 || address.rfind("unix-abstract:", 0) == 0) return true;
  const Result<std::pair<std::string, int>> where = split_host_port(address);
  return where && is_loopback_host(where->first);
}

}  // namespace balloon::net
