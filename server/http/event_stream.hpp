#pragma once
/// One WatchJob call seen from a thread that wants events one at a time with a timeout (the HTTP
/// gateway's Server-Sent-Events writer). Built on gRPC's client callback API with exactly one read in
/// flight: the next event is only asked for once the previous one was taken, so a slow browser holds
/// back the stream instead of filling memory. The thread that opened the stream owns it: only it calls
/// next() and close(), since those start reads and release the hold that keeps the call open. No gRPC
/// function is called under the stream's mutex (the in-process transport may run reactions inline).
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <grpcpp/grpcpp.h>

#include "balloon/v1/balloon.grpc.pb.h"

namespace balloon::http {

class JobEventStream : public grpc::ClientReadReactor<balloon::v1::JobEvent> {
 public:
  /// Starts WatchJob(job_id) on `stub`, sending `authorization` (empty: none) as the metadata of that name.
  /// The stream keeps itself alive until gRPC is done with it, whoever drops the last pointer.
  static std::shared_ptr<JobEventStream> open(balloon::v1::BalloonService::Stub& stub, const std::string& job_id,
                                              const std::string& authorization);

  enum class Next {
    Event,    ///< `*event` holds the next event
    End,      ///< the call is over; status() says how
    Timeout,  ///< nothing within the timeout
  };
  /// Waits at most `timeout` for the next event or the end of the call. Owner thread only.
  Next next(balloon::v1::JobEvent* event, std::chrono::milliseconds timeout);
  /// How the call ended; valid after next() returned End.
  grpc::Status status() const;
  /// Cancels the call; the owner's next() then returns End with CANCELLED. Any thread, any time.
  void cancel();
  /// The owner is finished with the stream: cancels the call if it is still on and lets gRPC wind it
  /// down. Owner thread only; idempotent. next() must not be called afterwards.
  void close();

  void OnReadDone(bool ok) override;
  void OnDone(const grpc::Status& status) override;

 private:
  JobEventStream() = default;
  /// Lets gRPC finish the call once no more reads will be started from outside a reaction. Owner thread.
  void release_hold();

  grpc::ClientContext m_context;
  balloon::v1::WatchJobRequest m_request;
  balloon::v1::JobEvent m_incoming;  ///< the buffer of the read in flight

  mutable std::mutex m_mutex;
  std::condition_variable m_changed;
  std::optional<balloon::v1::JobEvent> m_ready;  ///< read, not yet taken
  bool m_read_failed = false;                    ///< the last read found the stream's end
  bool m_hold_released = false;                  ///< owner thread only
  bool m_done = false;
  grpc::Status m_status;
  std::shared_ptr<JobEventStream> m_self;        ///< keeps the reactor alive until OnDone
};

}  // namespace balloon::http
