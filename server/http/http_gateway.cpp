#include "http/http_gateway.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <list>
#include <mutex>
#include <sstream>
#include <thread>

#include "balloon/v1/balloon.grpc.pb.h"
#include "http/event_stream.hpp"
#include "http/job_files.hpp"
#include "http/json_mapping.hpp"
#include "http/origin_policy.hpp"
#include "http/static_files.hpp"
#include "net/network_address.hpp"

namespace balloon::http {
namespace {

namespace v1 = balloon::v1;
using Stub = v1::BalloonService::Stub;
using Clock = std::chrono::steady_clock;

constexpr const char* JSON_TYPE = "application/json";
constexpr const char* TEXT_TYPE = "text/plain; charset=utf-8";
/// A comment line goes out this often on an otherwise quiet event stream (proxies and browsers close
/// connections that stay silent for long).
constexpr auto KEEPALIVE_INTERVAL = std::chrono::seconds(15);
/// How long an event stream waits for the next event before it checks on the client and the server.
constexpr auto EVENT_POLL = std::chrono::milliseconds(250);

bool is_api_path(const std::string& path) { return path == "/api" || path.rfind("/api/", 0) == 0; }

/// The API's error body; `http_status` overrides the status the code maps to (415 has no gRPC code).
void send_error(httplib::Response& res, grpc::StatusCode code, const std::string& message, int http_status = 0,
                const std::string& error_details = "") {
  res.status = http_status != 0 ? http_status : http_status_for(code);
  res.set_header("Cache-Control", "no-store");
  res.set_content(error_body(code, message, error_details), JSON_TYPE);
}

/// A failed call's status, with the fields its details name (google.rpc.BadRequest) as "fields".
void send_status(httplib::Response& res, const grpc::Status& status) {
  send_error(res, status.error_code(), status.error_message(), 0, status.error_details());
}

void send_message(httplib::Response& res, const google::protobuf::Message& message) {
  res.status = 200;
  res.set_header("Cache-Control", "no-store");
  res.set_content(message_to_json(message), JSON_TYPE);
}

/// The Authorization header to forward as gRPC metadata ("" when absent). gRPC refuses metadata values
/// outside printable ASCII, so such a header is answered here, in the service's words for a bad token.
bool authorization_of(const httplib::Request& req, httplib::Response& res, std::string* value) {
  value->clear();
  if (!req.has_header("Authorization")) return true;
  *value = req.get_header_value("Authorization");
  for (const char c : *value) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) {
      send_error(res, grpc::StatusCode::UNAUTHENTICATED, "the Authorization header must read 'Bearer <token>'");
      return false;
    }
  }
  return true;
}

/// The numeric host of a socket address, as httplib writes Request::remote_addr.
std::string numeric_host(const sockaddr_storage& address, socklen_t length) {
  char host[NI_MAXHOST];
  if (getnameinfo(reinterpret_cast<const sockaddr*>(&address), length, host, sizeof(host), nullptr, 0,
                  NI_NUMERICHOST) != 0)
    return "";
  return host;
}

int port_of(const sockaddr_storage& address) {
  if (address.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&address)->sin_port);
  if (address.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port);
  return -1;
}

/// The file descriptor of the connection a request came on, or -1. httplib 0.11 does not hand it to
/// handlers, and its DataSink::is_writable() only selects for writability, which stays true after the
/// peer has gone: without the socket, a stream on a quiet job would hold its worker thread until a
/// keepalive write failed (up to two intervals). The connection is found by its two endpoints; the
/// descriptor stays ours while the handler's worker thread serves it.
int find_connection_socket(const httplib::Request& req) {
  DIR* directory = opendir("/proc/self/fd");
  if (directory == nullptr) return -1;
  int found = -1;
  while (const dirent* entry = readdir(directory)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0') continue;
    sockaddr_storage local{}, peer{};
    socklen_t local_length = sizeof(local), peer_length = sizeof(peer);
    if (getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&local), &local_length) != 0) continue;
    if (getpeername(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&peer), &peer_length) != 0) continue;
    if (port_of(local) != req.local_port || port_of(peer) != req.remote_port) continue;
    if (numeric_host(peer, peer_length) != req.remote_addr) continue;
    found = static_cast<int>(fd);
    break;
  }
  closedir(directory);
  return found;
}

/// True when the peer has closed its side of the connection (a browser that navigated away or aborted).
bool peer_closed(int fd) {
  if (fd < 0) return false;
  pollfd entry{fd, POLLRDHUP, 0};
  return poll(&entry, 1, 0) > 0 && (entry.revents & (POLLRDHUP | POLLHUP | POLLERR | POLLNVAL)) != 0;
}

/// True for a `Content-Type` naming JSON: "application/json", any case, parameters such as charset allowed.
bool is_json_content_type(const std::string& value) {
  std::string media = value.substr(0, value.find(';'));
  while (!media.empty() && (media.back() == ' ' || media.back() == '\t')) media.pop_back();
  for (char& c : media) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return media == JSON_TYPE;
}

/// One place among the open event streams, given back when the stream's response is destroyed.
class StreamSlot {
 public:
  /// A slot if fewer than `limit` are taken, else nullptr.
  static std::unique_ptr<StreamSlot> take(std::atomic<int>& open, int limit) {
    int now = open.load();
    while (now < limit)
      if (open.compare_exchange_weak(now, now + 1)) return std::unique_ptr<StreamSlot>(new StreamSlot(open));
    return nullptr;
  }
  ~StreamSlot() { --m_open; }
  StreamSlot(const StreamSlot&) = delete;
  StreamSlot& operator=(const StreamSlot&) = delete;

 private:
  explicit StreamSlot(std::atomic<int>& open) : m_open(open) {}
  std::atomic<int>& m_open;
};

/// One open Server-Sent-Events response.
struct SseState {
  std::unique_ptr<StreamSlot> slot;
  std::shared_ptr<JobEventStream> stream;
  int socket = -1;
  Clock::time_point last_write = Clock::now();
  bool ended = false;
};

}  // namespace

struct HttpGateway::Internals {
  HttpGatewayOptions options;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<Stub> stub;
  std::unique_ptr<OriginPolicy> policy;     ///< set before the first request (it needs the bound port)
  std::atomic<int> open_streams{0};         ///< event streams holding a worker thread
  std::unique_ptr<httplib::Server> server;  ///< an httplib::SSLServer with TLS
  std::thread listener;
  int port = 0;

  std::mutex streams_mutex;
  std::list<std::weak_ptr<JobEventStream>> streams;  ///< open event streams, to end them at stop()
  bool stopping = false;                             ///< under streams_mutex
  std::atomic<bool> stopping_flag{false};            ///< the same, for the stream writers' polls
  std::mutex stop_mutex;
  bool stopped = false;

  void log(const std::string& line) const {
    if (options.log) options.log(line);
  }

  /// False (403 or 415 written) for a request this gateway must not serve: a Host or Origin the policy
  /// refuses (DNS rebinding, another site's page), or a body that is not declared JSON (a form or
  /// `text/plain` POST, which browsers send cross-site without asking first).
  bool admit(const httplib::Request& req, httplib::Response& res) const {
    if (req.get_header_value_count("Host") > 1 || req.get_header_value_count("Origin") > 1) {
      send_error(res, grpc::StatusCode::INVALID_ARGUMENT, "the request repeats its Host or Origin header");
      return false;
    }
    const std::string host = req.get_header_value("Host"), origin = req.get_header_value("Origin");
    const std::string refusal =
        policy->refusal(req.has_header("Host") ? &host : nullptr, req.has_header("Origin") ? &origin : nullptr);
    if (!refusal.empty()) {
      send_error(res, grpc::StatusCode::PERMISSION_DENIED, refusal);
      return false;
    }
    const bool may_write = req.method != "GET" && req.method != "HEAD" && req.method != "OPTIONS";
    if (may_write && (!req.body.empty() || req.has_header("Content-Type")) &&
        !is_json_content_type(req.get_header_value("Content-Type"))) {
      std::string got = req.get_header_value("Content-Type").substr(0, 80);
      for (char& c : got)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
      send_error(res, grpc::StatusCode::INVALID_ARGUMENT,
                 "a request body must be JSON sent with 'Content-Type: application/json'" +
                     (req.has_header("Content-Type") ? " (got '" + got + "')" : std::string(" (no Content-Type)")),
                 415);
      return false;
    }
    return true;
  }

  /// `handler` behind admit().
  httplib::Server::Handler admitted(std::function<void(const httplib::Request&, httplib::Response&)> handler) {
    return [this, handler = std::move(handler)](const httplib::Request& req, httplib::Response& res) {
      if (admit(req, res)) handler(req, res);
    };
  }

  /// A context carrying the request's Authorization; false (response written) on a malformed header.
  bool prepare(grpc::ClientContext& context, const httplib::Request& req, httplib::Response& res) const {
    std::string authorization;
    if (!authorization_of(req, res, &authorization)) return false;
    if (!authorization.empty()) context.AddMetadata("authorization", authorization);
    return true;
  }

  /// One unary call: request in, reply (or the service's status) out as JSON.
  template <class Request, class Reply>
  void unary(const httplib::Request& req, httplib::Response& res, const Request& request,
             grpc::Status (Stub::*method)(grpc::ClientContext*, const Request&, Reply*)) {
    grpc::ClientContext context;
    if (!prepare(context, req, res)) return;
    Reply reply;
    const grpc::Status status = (stub.get()->*method)(&context, request, &reply);
    if (!status.ok()) return send_status(res, status);
    send_message(res, reply);
  }

  /// Parses the body into `message`; false (400 written) when it is not valid JSON for it.
  static bool parse_body(const httplib::Request& req, httplib::Response& res, google::protobuf::Message* message) {
    const std::string problem = json_to_message(req.body, message);
    if (problem.empty()) return true;
    send_error(res, grpc::StatusCode::INVALID_ARGUMENT, problem);
    return false;
  }

  void list_jobs(const httplib::Request& req, httplib::Response& res) {
    v1::ListJobsRequest request;
    if (req.has_param("state")) {
      v1::JobState state = v1::JOB_STATE_UNSPECIFIED;
      const std::string name = req.get_param_value("state");
      if (!v1::JobState_Parse(name, &state))
        return send_error(res, grpc::StatusCode::INVALID_ARGUMENT,
                          "state: unknown job state '" + name +
                              "' (JOB_STATE_QUEUED, JOB_STATE_RUNNING, JOB_STATE_COMPLETED, JOB_STATE_FAILED or "
                              "JOB_STATE_CANCELLED)");
      request.set_state(state);
    }
    if (req.has_param("page_size")) {
      const std::string text = req.get_param_value("page_size");
      char* end = nullptr;
      const long size = std::strtol(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || size < 0 || size > 1000000)
        return send_error(res, grpc::StatusCode::INVALID_ARGUMENT, "page_size: '" + text + "' is not a number of jobs");
      request.set_page_size(static_cast<int>(size));
    }
    if (req.has_param("page_token")) request.set_page_token(req.get_param_value("page_token"));
    unary(req, res, request, &Stub::ListJobs);
  }

  void get_result(const httplib::Request& req, httplib::Response& res) {
    v1::GetResultRequest request;
    request.set_job_id(req.matches[1]);
    if (req.has_param("format")) {
      v1::MeshFormat format = v1::MESH_FORMAT_UNSPECIFIED;
      const std::string name = req.get_param_value("format");
      if (!v1::MeshFormat_Parse(name, &format))
        return send_error(res, grpc::StatusCode::INVALID_ARGUMENT,
                          "format: unknown mesh format '" + name + "' (MESH_FORMAT_OBJ, MESH_FORMAT_STL or MESH_FORMAT_PLY)");
      request.set_format(format);
    }
    unary(req, res, request, &Stub::GetResult);
  }

  void put_material(const httplib::Request& req, httplib::Response& res) {
    v1::PutMaterialRequest request;
    if (!parse_body(req, res, request.mutable_material())) return;
    const std::string name = req.matches[1];
    if (!request.material().name().empty() && request.material().name() != name)
      return send_error(res, grpc::StatusCode::INVALID_ARGUMENT,
                        "the material's name '" + request.material().name() + "' differs from the name in the path '" +
                            name + "'");
    request.mutable_material()->set_name(name);
    unary(req, res, request, &Stub::PutMaterial);
  }

  void get_file(const httplib::Request& req, httplib::Response& res) {
    const std::string job_id = req.matches[1];
    const std::string name = req.matches[2];
    if (!is_job_file_name(name))
      return send_error(res, grpc::StatusCode::NOT_FOUND, "unknown file '" + name + "': " + JOB_FILE_NAMES);
    grpc::ClientContext context;
    if (!prepare(context, req, res)) return;
    v1::GetResultRequest request;
    request.set_job_id(job_id);
    request.set_format(v1::MESH_FORMAT_OBJ);
    v1::JobResult result;
    const grpc::Status status = stub->GetResult(&context, request, &result);
    if (!status.ok()) return send_status(res, status);
    JobFile file = job_file(result, name);
    if (!file.status.ok()) return send_status(res, file.status);
    res.status = 200;
    res.set_header("Cache-Control", "no-store");
    res.set_header("Content-Disposition", "attachment; filename=\"" + name + "\"");
    res.set_content(std::move(file.bytes), file.content_type);
  }

  void watch_events(const httplib::Request& req, httplib::Response& res) {
    const std::string job_id = req.matches[1];
    std::unique_ptr<StreamSlot> slot = StreamSlot::take(open_streams, options.max_event_streams);
    if (!slot)
      return send_error(res, grpc::StatusCode::UNAVAILABLE,
                        "too many open event streams (" + std::to_string(options.max_event_streams) +
                            ", --http-max-event-streams): close one or try again later");
    std::string authorization;
    if (!authorization_of(req, res, &authorization)) return;
    // The job is looked up first so that a bad token or an unknown id is an HTTP error, not a stream
    // that opens and ends at once.
    {
      grpc::ClientContext context;
      if (!authorization.empty()) context.AddMetadata("authorization", authorization);
      v1::GetJobRequest request;
      request.set_job_id(job_id);
      v1::Job job;
      const grpc::Status status = stub->GetJob(&context, request, &job);
      if (!status.ok()) return send_status(res, status);
    }
    auto state = std::make_shared<SseState>();
    state->slot = std::move(slot);
    {
      std::lock_guard lock(streams_mutex);
      if (stopping) return send_error(res, grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
      state->stream = JobEventStream::open(*stub, job_id, authorization);
      for (auto it = streams.begin(); it != streams.end();) it = it->expired() ? streams.erase(it) : std::next(it);
      streams.push_back(state->stream);
    }
    state->socket = find_connection_socket(req);
    res.status = 200;
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");  // a reverse proxy must not hold events back
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, state](size_t /*offset*/, httplib::DataSink& sink) { return write_events(*state, sink); },
        [state](bool /*success*/) { state->stream->close(); });
  }

  /// One turn of an event stream: the next event, the end, or a check on the client. False drops the
  /// connection (the client is gone).
  bool write_events(SseState& state, httplib::DataSink& sink) {
    const auto write = [&](const std::string& text) {
      state.last_write = Clock::now();
      return sink.write(text.data(), text.size());
    };
    try {
      if (state.ended) {
        sink.done();
        return true;
      }
      v1::JobEvent event;
      switch (state.stream->next(&event, EVENT_POLL)) {
        case JobEventStream::Next::Event:
          return write("event: job\ndata: " + message_to_json(event) + "\n\n");
        case JobEventStream::Next::End: {
          grpc::Status status = state.stream->status();
          if (stopping_flag && !status.ok())
            status = grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
          state.ended = true;
          const bool written = write("event: end\ndata: " + status_json(status.error_code(), status.error_message()) + "\n\n");
          sink.done();
          return written;
        }
        case JobEventStream::Next::Timeout:
          if (peer_closed(state.socket)) return false;
          if (stopping_flag) state.stream->cancel();  // a stream opened as stop() ran: ends at the next turn
          if (Clock::now() - state.last_write >= KEEPALIVE_INTERVAL) return write(": keepalive\n\n");
          return true;
      }
    } catch (const std::exception& error) {
      log(std::string("http: event stream: internal error: ") + error.what());
    }
    return false;
  }

  void serve_static(const httplib::Request& req, httplib::Response& res) {
    if (is_api_path(req.path))
      return send_error(res, grpc::StatusCode::NOT_FOUND, "no API endpoint " + req.method + " " + req.path);
    const StaticLookup lookup = find_static_file(options.web_root, req.path);
    if (lookup.http_status != 200) {
      res.status = lookup.http_status;
      res.set_content(lookup.message, TEXT_TYPE);
      return;
    }
    std::ifstream in(lookup.file, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in) {
      res.status = 404;
      res.set_content("cannot read " + req.path + "\n", TEXT_TYPE);
      return;
    }
    res.status = 200;
    res.set_header("Cache-Control", "no-cache");
    res.set_content(bytes.str(), content_type_for(lookup.file));
  }

  void register_routes() {
    // Not behind the Host/Origin check: it tells nothing a rebinding page could use, and balancers and
    // probes call it by address, with a Host no gateway can predict.
    server->Get("/api/v1/health", [](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-store");
      res.set_content("{\"status\":\"ok\"}", JSON_TYPE);
    });
    server->Get("/api/v1/materials", admitted([this](const httplib::Request& req, httplib::Response& res) {
      unary(req, res, v1::ListMaterialsRequest(), &Stub::ListMaterials);
    }));
    server->Get(R"(/api/v1/materials/([^/]+))", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::GetMaterialRequest request;
      request.set_name(req.matches[1]);
      unary(req, res, request, &Stub::GetMaterial);
    }));
    server->Put(R"(/api/v1/materials/([^/]+))",
               admitted([this](const httplib::Request& req, httplib::Response& res) { put_material(req, res); }));
    server->Delete(R"(/api/v1/materials/([^/]+))", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::DeleteMaterialRequest request;
      request.set_name(req.matches[1]);
      unary(req, res, request, &Stub::DeleteMaterial);
    }));
    server->Post("/api/v1/jobs", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::SubmitJobRequest request;
      if (!parse_body(req, res, &request)) return;
      unary(req, res, request, &Stub::SubmitJob);
    }));
    server->Get("/api/v1/jobs", admitted([this](const httplib::Request& req, httplib::Response& res) { list_jobs(req, res); }));
    server->Get(R"(/api/v1/jobs/([^/]+))", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::GetJobRequest request;
      request.set_job_id(req.matches[1]);
      unary(req, res, request, &Stub::GetJob);
    }));
    server->Post(R"(/api/v1/jobs/([^/]+)/cancel)", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::CancelJobRequest request;  // the body, if any ("{}"), carries nothing
      request.set_job_id(req.matches[1]);
      unary(req, res, request, &Stub::CancelJob);
    }));
    server->Delete(R"(/api/v1/jobs/([^/]+))", admitted([this](const httplib::Request& req, httplib::Response& res) {
      v1::DeleteJobRequest request;
      request.set_job_id(req.matches[1]);
      unary(req, res, request, &Stub::DeleteJob);
    }));
    server->Get(R"(/api/v1/jobs/([^/]+)/result)",
               admitted([this](const httplib::Request& req, httplib::Response& res) { get_result(req, res); }));
    server->Get(R"(/api/v1/jobs/([^/]+)/events)",
               admitted([this](const httplib::Request& req, httplib::Response& res) { watch_events(req, res); }));
    server->Get(R"(/api/v1/jobs/([^/]+)/files/([^/]+))",
               admitted([this](const httplib::Request& req, httplib::Response& res) { get_file(req, res); }));
    // Everything else is the page (registered last: handlers match in order).
    server->Get(".*", admitted([this](const httplib::Request& req, httplib::Response& res) { serve_static(req, res); }));

    // Responses httplib makes itself (no route, body too large, unreadable request) get the API's error
    // body under /api and plain text elsewhere. Responses with a body are ours: left alone.
    server->set_error_handler(httplib::Server::HandlerWithResponse([this](const httplib::Request& req,
                                                                         httplib::Response& res) {
      if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
      grpc::StatusCode code = grpc::StatusCode::INTERNAL;
      std::string message = "HTTP status " + std::to_string(res.status);
      if (res.status == 404) {
        code = grpc::StatusCode::NOT_FOUND;
        message = "no API endpoint " + req.method + " " + req.path;
      } else if (res.status == 413) {
        code = grpc::StatusCode::RESOURCE_EXHAUSTED;
        // httplib caps form-encoded bodies at 8 KiB whatever the limit: curl's default Content-Type.
        if (req.get_header_value("Content-Type").rfind("application/x-www-form-urlencoded", 0) == 0)
          message = "a form-encoded request body is limited to 8192 bytes: send JSON with 'Content-Type: "
                    "application/json'";
        else
          message = "the request body is larger than the server's limit of " + std::to_string(options.max_body_bytes) +
                    " bytes (--max-message-mb)";
      } else if (res.status == 400 || res.status == 414 || res.status == 416) {
        code = grpc::StatusCode::INVALID_ARGUMENT;
        message = "malformed HTTP request (status " + std::to_string(res.status) + ")";
      }
      if (is_api_path(req.path)) {
        res.set_content(error_body(code, message), JSON_TYPE);
      } else {
        res.set_content(message + "\n", TEXT_TYPE);
      }
      return httplib::Server::HandlerResponse::Handled;
    }));
    server->set_exception_handler([this](const httplib::Request& req, httplib::Response& res, std::exception_ptr error) {
      std::string what = "unknown exception";
      try {
        if (error) std::rethrow_exception(error);
      } catch (const std::exception& e) {
        what = e.what();
      } catch (...) {
      }
      log("http: " + req.method + " " + req.path + ": internal error: " + what);
      send_error(res, grpc::StatusCode::INTERNAL, "internal error in the HTTP gateway");
    });
  }
};

HttpGateway::HttpGateway(std::unique_ptr<Internals> internals) : m_internals(std::move(internals)) {}

HttpGateway::~HttpGateway() { stop(); }

Result<std::unique_ptr<HttpGateway>> HttpGateway::start(const HttpGatewayOptions& options,
                                                        std::shared_ptr<grpc::Channel> channel) {
  Result<std::pair<std::string, int>> where = net::split_host_port(options.address, "HTTP address");
  if (!where) return fail(where.error());
  if (options.threads < 2) return fail("the HTTP gateway needs at least 2 threads");
  if (options.max_event_streams < 1) return fail("the HTTP gateway needs room for at least 1 event stream");
  std::vector<WebOrigin> allowed;
  for (const std::string& text : options.allowed_origins) {
    Result<WebOrigin> origin = parse_origin(text);
    if (!origin) return fail("--http-allowed-origin: " + origin.error());
    allowed.push_back(*origin);
  }
  const bool tls = !options.tls_cert_file.empty() || !options.tls_key_file.empty();
  auto internals = std::make_unique<Internals>();
  if (tls) {
    if (options.tls_cert_file.empty() || options.tls_key_file.empty())
      return fail("HTTPS needs both --http-tls-cert and --http-tls-key");
    for (const std::string* file : {&options.tls_cert_file, &options.tls_key_file})
      if (!std::ifstream(*file)) return fail("cannot read HTTP TLS file '" + *file + "'");
    auto server = std::make_unique<httplib::SSLServer>(options.tls_cert_file.c_str(), options.tls_key_file.c_str());
    if (!server->is_valid())
      return fail("cannot use '" + options.tls_cert_file + "' and '" + options.tls_key_file +
                  "' as the HTTP TLS certificate chain and key (PEM files of a matching pair expected)");
    internals->server = std::move(server);
  } else {
    internals->server = std::make_unique<httplib::Server>();
  }
  internals->options = options;
  internals->channel = std::move(channel);
  internals->stub = v1::BalloonService::NewStub(internals->channel);
  // Event streams hold a thread each, and there are at most max_event_streams of them: the rest of the
  // pool always serves the other requests.
  const auto threads = static_cast<size_t>(options.threads) + static_cast<size_t>(options.max_event_streams);
  internals->server->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  internals->server->set_payload_max_length(options.max_body_bytes);
  internals->register_routes();

  const auto& [host, port] = *where;
  if (port == 0) {
    internals->port = internals->server->bind_to_any_port(host);
    if (internals->port < 0) return fail("cannot listen on HTTP address '" + options.address + "'");
  } else {
    if (!internals->server->bind_to_port(host, port))
      return fail("cannot listen on HTTP address '" + options.address + "' (address in use or invalid)");
    internals->port = port;
  }
  internals->policy = std::make_unique<OriginPolicy>(tls, internals->port, std::move(allowed));
  Internals* raw = internals.get();
  internals->listener = std::thread([raw] { raw->server->listen_after_bind(); });
  // stop() is a no-op until the server runs: wait for it so that a quick stop cannot be lost.
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (!internals->server->is_running() && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!internals->server->is_running()) {
    internals->listener.join();  // listen_after_bind returned: it failed
    return fail("the HTTP server on '" + options.address + "' did not start");
  }
  return std::unique_ptr<HttpGateway>(new HttpGateway(std::move(internals)));
}

int HttpGateway::port() const { return m_internals->port; }

void HttpGateway::stop() {
  std::lock_guard stop_lock(m_internals->stop_mutex);
  if (m_internals->stopped) return;
  m_internals->stopped = true;
  {
    std::lock_guard lock(m_internals->streams_mutex);
    m_internals->stopping = true;
    m_internals->stopping_flag = true;
    for (const auto& weak : m_internals->streams)
      if (auto stream = weak.lock()) stream->cancel();
    m_internals->streams.clear();
  }
  m_internals->server->stop();
  if (m_internals->listener.joinable()) m_internals->listener.join();
}

}  // namespace balloon::http
