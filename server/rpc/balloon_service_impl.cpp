#include "rpc/balloon_service_impl.hpp"

#include <mutex>

#include "google/rpc/error_details.pb.h"
#include "google/rpc/status.pb.h"
#include "service/shard_name.hpp"

namespace balloon::rpc {
namespace {

namespace v1 = balloon::v1;
using service::ServiceStatus;
using service::StatusCode;

constexpr std::string_view BEARER = "Bearer ";

/// Streams one watch channel to one client. All reactor state changes happen under m_mutex; StartWrite
/// and Finish are called outside it, so a reaction that runs inline cannot deadlock.
class WatchReactor final : public grpc::ServerWriteReactor<v1::JobEvent> {
 public:
  WatchReactor(service::JobHandler& jobs, std::shared_ptr<service::WatchChannel> channel)
      : m_jobs(jobs), m_channel(std::move(channel)) {
    m_channel->set_notifier([this] { pump(); });
    pump();  // events queued before the notifier was set
  }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard lock(m_mutex);
      m_write_in_flight = false;
      if (!ok) {
        // The client went away; OnCancel or OnDone follows. Finish once.
        if (m_finished) return;
        m_finished = true;
      }
    }
    if (!ok) {
      Finish(grpc::Status(grpc::StatusCode::CANCELLED, "stream write failed"));
      return;
    }
    pump();
  }

  void OnCancel() override {
    {
      std::lock_guard lock(m_mutex);
      if (m_finished || m_write_in_flight) return;  // OnWriteDone(false) will finish a write in flight
      m_finished = true;
    }
    Finish(grpc::Status::CANCELLED);
  }

  void OnDone() override {
    m_channel->set_notifier(nullptr);  // waits for a notification in progress: no call into a dead reactor
    m_jobs.unwatch(m_channel);
    delete this;
  }

 private:
  void pump() {
    enum class Action { None, Write, Finish } action = Action::None;
    grpc::Status final_status;
    {
      std::lock_guard lock(m_mutex);
      if (m_write_in_flight || m_finished) return;
      if (auto event = m_channel->pop()) {
        m_current = std::move(*event);
        m_write_in_flight = true;
        action = Action::Write;
      } else if (m_channel->finished()) {
        m_finished = true;
        final_status = to_grpc_status(m_channel->final_status());
        action = Action::Finish;
      }
    }
    if (action == Action::Write) StartWrite(&m_current);
    if (action == Action::Finish) Finish(final_status);
  }

  service::JobHandler& m_jobs;
  std::shared_ptr<service::WatchChannel> m_channel;
  std::mutex m_mutex;
  v1::JobEvent m_current;
  bool m_write_in_flight = false;
  bool m_finished = false;
};

}  // namespace

grpc::Status to_grpc_status(const ServiceStatus& status) {
  grpc::StatusCode code = grpc::StatusCode::INTERNAL;
  switch (status.code) {
    case StatusCode::Ok: return grpc::Status::OK;
    case StatusCode::InvalidArgument: code = grpc::StatusCode::INVALID_ARGUMENT; break;
    case StatusCode::NotFound: code = grpc::StatusCode::NOT_FOUND; break;
    case StatusCode::ResourceExhausted: code = grpc::StatusCode::RESOURCE_EXHAUSTED; break;
    case StatusCode::Unauthenticated: code = grpc::StatusCode::UNAUTHENTICATED; break;
    case StatusCode::PermissionDenied: code = grpc::StatusCode::PERMISSION_DENIED; break;
    case StatusCode::FailedPrecondition: code = grpc::StatusCode::FAILED_PRECONDITION; break;
    case StatusCode::Unimplemented: code = grpc::StatusCode::UNIMPLEMENTED; break;
    case StatusCode::Unavailable: code = grpc::StatusCode::UNAVAILABLE; break;
    case StatusCode::Cancelled: code = grpc::StatusCode::CANCELLED; break;
    case StatusCode::Internal: code = grpc::StatusCode::INTERNAL; break;
  }
  if (status.fields.empty()) return grpc::Status(code, status.message);
  // The standard rich error model: a google.rpc.Status holding one google.rpc.BadRequest, serialized into
  // the status details, so any gRPC client finds the fields without reading the message.
  google::rpc::BadRequest bad_request;
  for (const service::FieldViolation& field : status.fields) {
    google::rpc::BadRequest::FieldViolation* violation = bad_request.add_field_violations();
    violation->set_field(field.field);
    violation->set_description(field.description);
  }
  google::rpc::Status details;
  details.set_code(static_cast<int>(code));
  details.set_message(status.message);
  details.add_details()->PackFrom(bad_request);
  return grpc::Status(code, status.message, details.SerializeAsString());
}

BalloonServiceImpl::BalloonServiceImpl(service::JobHandler& jobs, service::MaterialHandler& materials,
                                       const service::TokenTable* tokens, std::function<void(const std::string&)> log,
                                       std::string shard_name)
    : m_jobs(jobs), m_materials(materials), m_tokens(tokens), m_log(std::move(log)), m_shard_name(std::move(shard_name)) {}

grpc::Status BalloonServiceImpl::authenticate(grpc::ServerContextBase* context, service::Caller* caller) const {
  if (m_tokens == nullptr) {
    caller->tenant = service::LOCAL_TENANT;
    caller->may_raise_priority = true;
    return grpc::Status::OK;
  }
  const auto& metadata = context->client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end())
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "missing 'authorization: Bearer <token>' metadata");
  const std::string_view value(it->second.data(), it->second.size());
  if (value.substr(0, BEARER.size()) != BEARER)
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "authorization metadata must read 'Bearer <token>'");
  const std::optional<service::Caller> found = m_tokens->caller_for(value.substr(BEARER.size()));
  if (!found) return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "unknown token");
  *caller = *found;
  return grpc::Status::OK;
}

template <class Request, class Reply, class Handler>
grpc::Status BalloonServiceImpl::call(const char* method, grpc::ServerContextBase* context, const Request* request,
                                      Reply* reply, Handler&& handler) {
  service::Caller caller;
  if (grpc::Status status = authenticate(context, &caller); !status.ok()) return status;
  return dispatch(method, caller, m_shard_name, m_log, *request, reply, std::forward<Handler>(handler));
}

grpc::Status BalloonServiceImpl::SubmitJob(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                                           v1::SubmitJobResponse* reply) {
  return call("SubmitJob", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_jobs.submit(c, q, r); });
}

grpc::Status BalloonServiceImpl::GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request, v1::Job* reply) {
  return call("GetJob", context, request, reply, [this](auto& c, auto& q, auto* r) { return m_jobs.get(c, q, r); });
}

grpc::Status BalloonServiceImpl::ListJobs(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                                          v1::ListJobsResponse* reply) {
  return call("ListJobs", context, request, reply, [this](auto& c, auto& q, auto* r) { return m_jobs.list(c, q, r); });
}

grpc::Status BalloonServiceImpl::CancelJob(grpc::ServerContext* context, const v1::CancelJobRequest* request,
                                           v1::Job* reply) {
  return call("CancelJob", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_jobs.cancel(c, q, r); });
}

grpc::Status BalloonServiceImpl::DeleteJob(grpc::ServerContext* context, const v1::DeleteJobRequest* request,
                                           v1::DeleteJobResponse* reply) {
  return call("DeleteJob", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_jobs.remove(c, q, r); });
}

grpc::Status BalloonServiceImpl::GetResult(grpc::ServerContext* context, const v1::GetResultRequest* request,
                                           v1::JobResult* reply) {
  return call("GetResult", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_jobs.result(c, q, r); });
}

grpc::Status BalloonServiceImpl::PutMaterial(grpc::ServerContext* context, const v1::PutMaterialRequest* request,
                                             v1::Material* reply) {
  return call("PutMaterial", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_materials.put(c, q, r); });
}

grpc::Status BalloonServiceImpl::GetMaterial(grpc::ServerContext* context, const v1::GetMaterialRequest* request,
                                             v1::Material* reply) {
  return call("GetMaterial", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_materials.get(c, q, r); });
}

grpc::Status BalloonServiceImpl::ListMaterials(grpc::ServerContext* context, const v1::ListMaterialsRequest* request,
                                               v1::ListMaterialsResponse* reply) {
  return call("ListMaterials", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_materials.list(c, q, r); });
}

grpc::Status BalloonServiceImpl::DeleteMaterial(grpc::ServerContext* context, const v1::DeleteMaterialRequest* request,
                                                v1::DeleteMaterialResponse* reply) {
  return call("DeleteMaterial", context, request, reply,
              [this](auto& c, auto& q, auto* r) { return m_materials.remove(c, q, r); });
}

grpc::ServerWriteReactor<v1::JobEvent>* BalloonServiceImpl::WatchJob(grpc::CallbackServerContext* context,
                                                                     const v1::WatchJobRequest* request) {
  service::Caller caller;
  grpc::Status status = authenticate(context, &caller);
  if (status.ok()) status = to_grpc_status(service::check_job_shard(m_shard_name, request->job_id()));
  std::shared_ptr<service::WatchChannel> channel;
  if (status.ok()) {
    try {
      status = to_grpc_status(m_jobs.watch(caller, *request, &channel));
    } catch (const std::exception& error) {
      if (m_log) m_log(std::string("WatchJob: internal error: ") + error.what());
      status = grpc::Status(grpc::StatusCode::INTERNAL, "internal error in WatchJob");
    }
  }
  if (!status.ok()) {
    // A reactor that finishes at once with the error.
    class FailedReactor final : public grpc::ServerWriteReactor<v1::JobEvent> {
     public:
      explicit FailedReactor(const grpc::Status& status) { Finish(status); }
      void OnDone() override { delete this; }
    };
    return new FailedReactor(status);
  }
  return new WatchReactor(m_jobs, std::move(channel));
}

}  // namespace balloon::rpc
