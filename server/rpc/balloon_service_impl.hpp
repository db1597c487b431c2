#pragma once
/// The gRPC edge of the service: authenticates the caller, converts, forwards to the handlers, and maps
/// their statuses onto grpc::Status. The only place besides grpc_server that sees gRPC types.
/// Unary calls use the synchronous API (handlers may block on the store); WatchJob is a callback
/// reactor that keeps exactly one write in flight.
#include <functional>
#include <string>

#include "balloon/v1/balloon.grpc.pb.h"
#include "rpc/dispatch.hpp"
#include "service/job_handler.hpp"
#include "service/material_handler.hpp"
#include "service/token_table.hpp"

namespace balloon::rpc {

using BalloonServiceBase =
    balloon::v1::BalloonService::WithCallbackMethod_WatchJob<balloon::v1::BalloonService::Service>;

class BalloonServiceImpl final : public BalloonServiceBase {
 public:
  /// `tokens` null: no authentication, every caller is the local tenant. `log` may be empty. A job call
  /// whose id names another shard than `shard_name` answers FAILED_PRECONDITION (service/shard_name).
  BalloonServiceImpl(service::JobHandler& jobs, service::MaterialHandler& materials, const service::TokenTable* tokens,
                     std::function<void(const std::string&)> log, std::string shard_name = {});

  grpc::Status SubmitJob(grpc::ServerContext* context, const balloon::v1::SubmitJobRequest* request,
                         balloon::v1::SubmitJobResponse* reply) override;
  grpc::Status GetJob(grpc::ServerContext* context, const balloon::v1::GetJobRequest* request,
                      balloon::v1::Job* reply) override;
  grpc::Status ListJobs(grpc::ServerContext* context, const balloon::v1::ListJobsRequest* request,
                        balloon::v1::ListJobsResponse* reply) override;
  grpc::Status CancelJob(grpc::ServerContext* context, const balloon::v1::CancelJobRequest* request,
                         balloon::v1::Job* reply) override;
  grpc::Status DeleteJob(grpc::ServerContext* context, const balloon::v1::DeleteJobRequest* request,
                         balloon::v1::DeleteJobResponse* reply) override;
  grpc::ServerWriteReactor<balloon::v1::JobEvent>* WatchJob(grpc::CallbackServerContext* context,
                                                            const balloon::v1::WatchJobRequest* request) override;
  grpc::Status GetResult(grpc::ServerContext* context, const balloon::v1::GetResultRequest* request,
                         balloon::v1::JobResult* reply) override;
  grpc::Status PutMaterial(grpc::ServerContext* context, const balloon::v1::PutMaterialRequest* request,
                           balloon::v1::Material* reply) override;
  grpc::Status GetMaterial(grpc::ServerContext* context, const balloon::v1::GetMaterialRequest* request,
                           balloon::v1::Material* reply) override;
  grpc::Status ListMaterials(grpc::ServerContext* context, const balloon::v1::ListMaterialsRequest* request,
                             balloon::v1::ListMaterialsResponse* reply) override;
  grpc::Status DeleteMaterial(grpc::ServerContext* context, const balloon::v1::DeleteMaterialRequest* request,
                              balloon::v1::DeleteMaterialResponse* reply) override;

 private:
  template <class Request, class Reply, class Handler>
  grpc::Status call(const char* method, grpc::ServerContextBase* context, const Request* request, Reply* reply,
                    Handler&& handler);
  /// The caller for this call's metadata, or UNAUTHENTICATED.
  grpc::Status authenticate(grpc::ServerContextBase* context, service::Caller* caller) const;

  service::JobHandler& m_jobs;
  service::MaterialHandler& m_materials;
  const service::TokenTable* m_tokens;
  std::function<void(const std::string&)> m_log;
  std::string m_shard_name;
};


}  // namespace balloon::rpc
