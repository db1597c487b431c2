#include "http/event_stream.hpp"

namespace balloon::http {

namespace v1 = balloon::v1;

std::shared_ptr<JobEventStream> JobEventStream::open(v1::BalloonService::Stub& stub, const std::string& job_id,
                                                     const std::string& authorization) {
  std::shared_ptr<JobEventStream> stream(new JobEventStream());
  stream->m_self = stream;
  if (!authorization.empty()) stream->m_context.AddMetadata("authorization", authorization);
  stream->m_request.set_job_id(job_id);
  stub.async()->WatchJob(&stream->m_context, &stream->m_request, stream.get());
  // Reads after the first are started from next(), outside any reaction: the hold keeps OnDone from
  // running (and the call from being torn down) until release_hold().
  stream->AddHold();
  stream->StartRead(&stream->m_incoming);
  stream->StartCall();
  return stream;
}

JobEventStream::Next JobEventStream::next(v1::JobEvent* event, std::chrono::milliseconds timeout) {
  bool got_event = false;
  {
    std::unique_lock lock(m_mutex);
    const bool woken = m_changed.wait_for(lock, timeout, [&] { return m_ready || m_read_failed || m_done; });
    if (!woken) return Next::Timeout;
    if (m_ready) {
      *event = std::move(*m_ready);
      m_ready.reset();
      got_event = true;
    }
  }
  if (got_event) {
    if (!m_hold_released) StartRead(&m_incoming);  // the hold is still ours, so the call is alive
    return Next::Event;
  }
  // The stream is over: let gRPC finish and wait for the status.
  release_hold();
  std::unique_lock lock(m_mutex);
  m_changed.wait(lock, [&] { return m_done; });
  return Next::End;
}

grpc::Status JobEventStream::status() const {
  std::lock_guard lock(m_mutex);
  return m_status;
}

void JobEventStream::cancel() { m_context.TryCancel(); }

void JobEventStream::close() {
  m_context.TryCancel();
  release_hold();
}

void JobEventStream::release_hold() {
  if (m_hold_released) return;
  m_hold_released = true;
  RemoveHold();
}

void JobEventStream::OnReadDone(bool ok) {
  std::lock_guard lock(m_mutex);
  if (ok)
    m_ready = std::move(m_incoming);
  else
    m_read_failed = true;
  m_changed.notify_all();
}

void JobEventStream::OnDone(const grpc::Status& status) {
  std::shared_ptr<JobEventStream> self;
  {
    std::lock_guard lock(m_mutex);
    m_done = true;
    m_status = status;
    self = std::move(m_self);
    m_changed.notify_all();
  }
  // `self` may be the last reference: this object can end here, after the lock is gone.
}

}  // namespace balloon::http
