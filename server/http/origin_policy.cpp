#include "http/origin_policy.hpp"

#include <cctype>

#include "net/network_address.hpp"

namespace balloon::http {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return out;
}

/// A header value fit for an error message: at most 80 characters, control bytes as '?'.
std::string quoted(std::string_view text) {
  std::string out(text.substr(0, 80));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return "'" + out + (text.size() > 80 ? "...'" : "'");
}

/// "HOST[:PORT]" / "[V6][:PORT]" -> (lower-case host, port or default_port); "" on success, else the problem.
std::string split_authority(std::string_view text, int default_port, std::string* host, int* port) {
  std::string_view port_text;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return "an IPv6 host needs a closing ']'";
    *host = lower(text.substr(1, close - 1));
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return "unexpected text after ']'";
      port_text = rest.substr(1);
      if (port_text.empty()) return "an empty port";
    }
  } else {
    const auto colon = text.find(':');
    *host = lower(text.substr(0, colon));
    if (colon != std::string_view::npos) {
      port_text = text.substr(colon + 1);
      if (port_text.empty()) return "an empty port";
    }
  }
  if (host->empty()) return "no host";
  for (const char c : *host)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_' || c == ':'))
      return "a character that cannot be in a host name";
  *port = default_port;
  if (!port_text.empty()) {
    if (port_text.size() > 5) return "a port outside 1..65535";
    int value = 0;
    for (const char c : port_text) {
      if (c < '0' || c > '9') return "a port that is not a number";
      value = value * 10 + (c - '0');
    }
    if (value < 1 || value > 65535) return "a port outside 1..65535";
    *port = value;
  }
  return "";
}

}  // namespace

Result<WebOrigin> parse_origin(std::string_view text) {
  const auto separator = text.find("://");
  if (separator == std::string_view::npos) return fail("origin " + quoted(text) + " must read SCHEME://HOST[:PORT]");
  WebOrigin origin;
  origin.scheme = lower(text.substr(0, separator));
  if (origin.scheme != "http" && origin.scheme != "https")
    return fail("origin " + quoted(text) + ": the scheme must be http or https");
  std::string_view authority = text.substr(separator + 3);
  if (!authority.empty() && authority.back() == '/') authority.remove_suffix(1);
  if (authority.find_first_of("/?#@") != std::string_view::npos)
    return fail("origin " + quoted(text) + " must be SCHEME://HOST[:PORT], without a path, query or user");
  const std::string problem = split_authority(authority, origin.scheme == "https" ? 443 : 80, &origin.host, &origin.port);
  if (!problem.empty()) return fail("origin " + quoted(text) + " has " + problem);
  return origin;
}

Result<std::pair<std::string, int>> parse_host_header(std::string_view text, int default_port) {
  std::string host;
  int port = 0;
  const std::string problem = split_authority(text, default_port, &host, &port);
  if (!problem.empty()) return fail("the Host header " + quoted(text) + " has " + problem);
  return std::make_pair(host, port);
}

OriginPolicy::OriginPolicy(bool tls, int port, std::vector<WebOrigin> allowed)
    : m_scheme(tls ? "https" : "http"), m_port(port), m_allowed(std::move(allowed)) {}

std::string OriginPolicy::refusal(const std::string* host, const std::string* origin) const {
  if (host == nullptr || host->empty()) return "the request has no Host header";
  const Result<std::pair<std::string, int>> where = parse_host_header(*host, m_scheme == "https" ? 443 : 80);
  if (!where) return where.error();
  // DNS rebinding changes the name, not the port or the address behind it: a proxy that forwards the
  // public name may change the port, so an allowed origin's host matches on the name alone.
  bool host_allowed = net::is_loopback_host(where->first) && where->second == m_port;
  for (const WebOrigin& allowed : m_allowed) host_allowed = host_allowed || allowed.host == where->first;
  if (!host_allowed)
    return "the Host header " + quoted(*host) + " names neither this server's loopback address with port " +
           std::to_string(m_port) + " nor an --http-allowed-origin host";
  if (origin == nullptr) return "";
  const Result<WebOrigin> from = parse_origin(*origin);
  if (from) {
    if (from->scheme == m_scheme && from->port == m_port && net::is_loopback_host(from->host)) return "";
    for (const WebOrigin& allowed : m_allowed)
      if (allowed == *from) return "";
  }
  return "cross-origin request from " + quoted(*origin) +
         " refused: only this server's own page or an --http-allowed-origin may call the API";
}

}  // namespace balloon::http
