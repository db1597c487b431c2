#pragma once
/// The service's API inside the caller's process, with no transport: the generated stub interface,
/// implemented by calling the same handlers the gRPC adapter calls, through the same dispatch (shard
/// check, status mapping). No gRPC server, no serialization, no threads of its own: the embedded CLI
/// service uses it. Only the synchronous calls exist (the CLI uses nothing else); the asynchronous ones
/// return null.
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "balloon/v1/balloon.grpc.pb.h"
#include "service/caller.hpp"
#include "service/job_handler.hpp"
#include "service/material_handler.hpp"

namespace balloon::rpc {

class DirectWatchReader;

class DirectStub final : public balloon::v1::BalloonService::StubInterface {
 public:
  /// Every call is made as `caller` (the embedded service has one user and no tokens).
  DirectStub(service::JobHandler& jobs, service::MaterialHandler& materials, service::Caller caller,
             std::function<void(const std::string&)> log = {});
  ~DirectStub() override;

  grpc::Status SubmitJob(grpc::ClientContext* context, const balloon::v1::SubmitJobRequest& request,
                         balloon::v1::SubmitJobResponse* response) override;
  grpc::Status GetJob(grpc::ClientContext* context, const balloon::v1::GetJobRequest& request,
                      balloon::v1::Job* response) override;
  grpc::Status ListJobs(grpc::ClientContext* context, const balloon::v1::ListJobsRequest& request,
                        balloon::v1::ListJobsResponse* response) override;
  grpc::Status CancelJob(grpc::ClientContext* context, const balloon::v1::CancelJobRequest& request,
                         balloon::v1::Job* response) override;
  grpc::Status DeleteJob(grpc::ClientContext* context, const balloon::v1::DeleteJobRequest& request,
                         balloon::v1::DeleteJobResponse* response) override;
  grpc::Status GetResult(grpc::ClientContext* context, const balloon::v1::GetResultRequest& request,
                         balloon::v1::JobResult* response) override;
  grpc::Status PutMaterial(grpc::ClientContext* context, const balloon::v1::PutMaterialRequest& request,
                           balloon::v1::Material* response) override;
  grpc::Status GetMaterial(grpc::ClientContext* context, const balloon::v1::GetMaterialRequest& request,
                           balloon::v1::Material* response) override;
  grpc::Status ListMaterials(grpc::ClientContext* context, const balloon::v1::ListMaterialsRequest& request,
                             balloon::v1::ListMaterialsResponse* response) override;
  grpc::Status DeleteMaterial(grpc::ClientContext* context, const balloon::v1::DeleteMaterialRequest& request,
                              balloon::v1::DeleteMaterialResponse* response) override;

  /// Ends a WatchJob stream opened with `context`: its Read returns false and Finish gives CANCELLED.
  /// (ClientContext::TryCancel cannot reach a stream that has no gRPC call.) No-op for other contexts.
  void cancel(grpc::ClientContext* context);

 private:
  friend class DirectWatchReader;
  void forget(grpc::ClientContext* context);

  grpc::ClientReaderInterface<balloon::v1::JobEvent>* WatchJobRaw(
      grpc::ClientContext* context, const balloon::v1::WatchJobRequest& request) override;

  // Asynchronous variants: not offered in-process.
  using Queue = grpc::CompletionQueue;
  template <class R>
  using AsyncReply = grpc::ClientAsyncResponseReaderInterface<R>;
  AsyncReply<balloon::v1::SubmitJobResponse>* AsyncSubmitJobRaw(grpc::ClientContext*, const balloon::v1::SubmitJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::SubmitJobResponse>* PrepareAsyncSubmitJobRaw(grpc::ClientContext*, const balloon::v1::SubmitJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Job>* AsyncGetJobRaw(grpc::ClientContext*, const balloon::v1::GetJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Job>* PrepareAsyncGetJobRaw(grpc::ClientContext*, const balloon::v1::GetJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::ListJobsResponse>* AsyncListJobsRaw(grpc::ClientContext*, const balloon::v1::ListJobsRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::ListJobsResponse>* PrepareAsyncListJobsRaw(grpc::ClientContext*, const balloon::v1::ListJobsRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Job>* AsyncCancelJobRaw(grpc::ClientContext*, const balloon::v1::CancelJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Job>* PrepareAsyncCancelJobRaw(grpc::ClientContext*, const balloon::v1::CancelJobRequest&, Queue*) override { return nullptr; }
  grpc::ClientAsyncReaderInterface<balloon::v1::JobEvent>* AsyncWatchJobRaw(grpc::ClientContext*, const balloon::v1::WatchJobRequest&, Queue*, void*) override { return nullptr; }
  grpc::ClientAsyncReaderInterface<balloon::v1::JobEvent>* PrepareAsyncWatchJobRaw(grpc::ClientContext*, const balloon::v1::WatchJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::DeleteJobResponse>* AsyncDeleteJobRaw(grpc::ClientContext*, const balloon::v1::DeleteJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::DeleteJobResponse>* PrepareAsyncDeleteJobRaw(grpc::ClientContext*, const balloon::v1::DeleteJobRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::JobResult>* AsyncGetResultRaw(grpc::ClientContext*, const balloon::v1::GetResultRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::JobResult>* PrepareAsyncGetResultRaw(grpc::ClientContext*, const balloon::v1::GetResultRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Material>* AsyncPutMaterialRaw(grpc::ClientContext*, const balloon::v1::PutMaterialRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Material>* PrepareAsyncPutMaterialRaw(grpc::ClientContext*, const balloon::v1::PutMaterialRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Material>* AsyncGetMaterialRaw(grpc::ClientContext*, const balloon::v1::GetMaterialRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::Material>* PrepareAsyncGetMaterialRaw(grpc::ClientContext*, const balloon::v1::GetMaterialRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::ListMaterialsResponse>* AsyncListMaterialsRaw(grpc::ClientContext*, const balloon::v1::ListMaterialsRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::ListMaterialsResponse>* PrepareAsyncListMaterialsRaw(grpc::ClientContext*, const balloon::v1::ListMaterialsRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::DeleteMaterialResponse>* AsyncDeleteMaterialRaw(grpc::ClientContext*, const balloon::v1::DeleteMaterialRequest&, Queue*) override { return nullptr; }
  AsyncReply<balloon::v1::DeleteMaterialResponse>* PrepareAsyncDeleteMaterialRaw(grpc::ClientContext*, const balloon::v1::DeleteMaterialRequest&, Queue*) override { return nullptr; }

  service::JobHandler& m_jobs;
  service::MaterialHandler& m_materials;
  service::Caller m_caller;
  std::function<void(const std::string&)> m_log;
  std::mutex m_mutex;
  std::map<grpc::ClientContext*, DirectWatchReader*> m_watches;  // open streams by context, for cancel()
};

}  // namespace balloon::rpc
