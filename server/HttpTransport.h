#pragma once
// The connection layer under cpp-httplib's request parsing, so that no client can hold a worker:
//
// - BoundedServer replaces httplib's per-connection loop (Server::process_and_close_socket) with
//   one whose socket stream has a DEADLINE per request: headers and body must arrive within
//   `readTimeout` in total, however slowly the bytes trickle (httplib 0.11's own timeout restarts
//   with every byte, so a client sending one byte every 5 s held a worker forever). An idle
//   keep-alive connection is closed after `keepAliveTimeout`. Every accepted socket gets
//   TCP_NODELAY (the response's header and body are separate writes: Nagle against the client's
//   delayed ACK cost ~40 ms per request on a reused connection).
// - ElasticPool starts worker threads as connections need them, up to a cap, so a burst of slow
//   clients does not queue health checks behind them.
// - markCloseConnection(): a handler that stopped reading a body early (413) asks for the
//   connection to be closed after the response, since the rest of the body is still unread.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include <httplib.h>

namespace radiant::server {

class BoundedServer : public httplib::Server {
public:
  BoundedServer();
  struct Timeouts {
    double readS = 30;       // one request's headers and body, in total
    double keepAliveS = 2;   // idle between requests on one connection
    double writeS = 30;      // each write of the response may stall this long
  };
  void setTimeouts(const Timeouts& t) { timeouts_ = t; }

private:
  bool process_and_close_socket(socket_t sock) override;
  Timeouts timeouts_;
};

// Called by a handler on its worker thread: close this connection once the response is written.
void markCloseConnection();

class ElasticPool : public httplib::TaskQueue {
public:
  ElasticPool(std::size_t initialThreads, std::size_t maxThreads);
  ~ElasticPool() override;
  void enqueue(std::function<void()> fn) override;
  void shutdown() override;
  std::size_t threads();

private:
  void work();
  std::mutex mutex_;
  std::condition_variable cond_;
  std::deque<std::function<void()>> jobs_;
  std::vector<std::thread> threads_;
  std::size_t max_, idle_ = 0;
  bool stop_ = false;
};

}  // namespace radiant::server
