#include "rpc/direct_stub.hpp"

#include <chrono>
#include <condition_variable>

#include "rpc/dispatch.hpp"

namespace balloon::rpc {

namespace v1 = balloon::v1;

/// A WatchJob stream read straight from its watch channel: Read blocks until the worker publishes an
/// event, the job ends, the context's deadline passes or the stub cancels it.
class DirectWatchReader final : public grpc::ClientReaderInterface<v1::JobEvent> {
 public:
  /// `channel` null: the watch was refused with `status`.
  DirectWatchReader(DirectStub& stub, grpc::ClientContext* context, std::shared_ptr<service::WatchChannel> channel,
                    grpc::Status status)
      : m_stub(stub), m_context(context), m_channel(std::move(channel)), m_status(std::move(status)) {
    if (m_channel) m_channel->set_notifier([this] { wake(); });
  }

  ~DirectWatchReader() override {
    if (m_channel) {
      m_channel->set_notifier(nullptr);  // waits for a notification in progress
      m_stub.m_jobs.unwatch(m_channel);
    }
    m_stub.forget(m_context);
  }

  bool Read(v1::JobEvent* event) override {
    if (!m_channel) return false;
    const auto deadline = m_context->deadline();
    std::unique_lock lock(m_mutex);
    for (;;) {
      if (m_cancelled) {
        m_status = grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
        return false;
      }
      if (auto next = m_channel->pop()) {
        *event = std::move(*next);
        return true;
      }
      if (m_channel->finished()) {
        m_status = to_grpc_status(m_channel->final_status());
        return false;
      }
      if (deadline == std::chrono::system_clock::time_point::max()) {
        m_wake.wait(lock, [this] { return m_woken || m_cancelled; });
      } else if (!m_wake.wait_until(lock, deadline, [this] { return m_woken || m_cancelled; })) {
        m_status = grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "Deadline Exceeded");
        return false;
      }
      m_woken = false;
    }
  }

  grpc::Status Finish() override { return m_status; }
  bool NextMessageSize(std::uint32_t* size) override {
    *size = std::numeric_limits<std::uint32_t>::max();
    return true;
  }
  void WaitForInitialMetadata() override {}

  void cancel() {
    {
      std::lock_guard lock(m_mutex);
      m_cancelled = true;
    }
    m_wake.notify_all();
  }

 private:
  void wake() {
    {
      std::lock_guard lock(m_mutex);
      m_woken = true;
    }
    m_wake.notify_all();
  }

  DirectStub& m_stub;
  grpc::ClientContext* m_context;
  std::shared_ptr<service::WatchChannel> m_channel;
  grpc::Status m_status;
  std::mutex m_mutex;
  std::condition_variable m_wake;
  bool m_woken = false;
  bool m_cancelled = false;
};

DirectStub::DirectStub(service::JobHandler& jobs, service::MaterialHandler& materials, service::Caller caller,
                       std::function<void(const std::string&)> log)
    : m_jobs(jobs), m_materials(materials), m_caller(std::move(caller)), m_log(std::move(log)) {}

DirectStub::~DirectStub() = default;

namespace {
const std::string NO_SHARD;  // the embedded service is one process, never a shard
}

grpc::Status DirectStub::SubmitJob(grpc::ClientContext*, const v1::SubmitJobRequest& request,
                                   v1::SubmitJobResponse* response) {
  return dispatch("SubmitJob", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.submit(c, q, r); });
}

grpc::Status DirectStub::GetJob(grpc::ClientContext*, const v1::GetJobRequest& request, v1::Job* response) {
  return dispatch("GetJob", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.get(c, q, r); });
}

grpc::Status DirectStub::ListJobs(grpc::ClientContext*, const v1::ListJobsRequest& request,
                                  v1::ListJobsResponse* response) {
  return dispatch("ListJobs", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.list(c, q, r); });
}

grpc::Status DirectStub::CancelJob(grpc::ClientContext*, const v1::CancelJobRequest& request, v1::Job* response) {
  return dispatch("CancelJob", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.cancel(c, q, r); });
}

grpc::Status DirectStub::DeleteJob(grpc::ClientContext*, const v1::DeleteJobRequest& request,
                                   v1::DeleteJobResponse* response) {
  return dispatch("DeleteJob", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.remove(c, q, r); });
}

grpc::Status DirectStub::GetResult(grpc::ClientContext*, const v1::GetResultRequest& request,
                                   v1::JobResult* response) {
  return dispatch("GetResult", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_jobs.result(c, q, r); });
}

grpc::Status DirectStub::PutMaterial(grpc::ClientContext*, const v1::PutMaterialRequest& request,
                                     v1::Material* response) {
  return dispatch("PutMaterial", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_materials.put(c, q, r); });
}

grpc::Status DirectStub::GetMaterial(grpc::ClientContext*, const v1::GetMaterialRequest& request,
                                     v1::Material* response) {
  return dispatch("GetMaterial", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_materials.get(c, q, r); });
}

grpc::Status DirectStub::ListMaterials(grpc::ClientContext*, const v1::ListMaterialsRequest& request,
                                       v1::ListMaterialsResponse* response) {
  return dispatch("ListMaterials", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_materials.list(c, q, r); });
}

grpc::Status DirectStub::DeleteMaterial(grpc::ClientContext*, const v1::DeleteMaterialRequest& request,
                                        v1::DeleteMaterialResponse* response) {
  return dispatch("DeleteMaterial", m_caller, NO_SHARD, m_log, request, response,
                  [this](auto& c, auto& q, auto* r) { return m_materials.remove(c, q, r); });
}

grpc::ClientReaderInterface<v1::JobEvent>* DirectStub::WatchJobRaw(grpc::ClientContext* context,
                                                                   const v1::WatchJobRequest& request) {
  std::shared_ptr<service::WatchChannel> channel;
  int unused = 0;
  const grpc::Status status = dispatch("WatchJob", m_caller, NO_SHARD, m_log, request, &unused,
                                       [this, &channel](auto& c, auto& q, int*) { return m_jobs.watch(c, q, &channel); });
  auto* reader = new DirectWatchReader(*this, context, status.ok() ? std::move(channel) : nullptr, status);
  std::lock_guard lock(m_mutex);
  m_watches[context] = reader;
  return reader;
}

void DirectStub::cancel(grpc::ClientContext* context) {
  std::lock_guard lock(m_mutex);
  if (const auto it = m_watches.find(context); it != m_watches.end()) it->second->cancel();
}

void DirectStub::forget(grpc::ClientContext* context) {
  std::lock_guard lock(m_mutex);
  m_watches.erase(context);
}

}  // namespace balloon::rpc
