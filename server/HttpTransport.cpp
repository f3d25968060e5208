#include "server/HttpTransport.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

namespace radiant::server {

namespace {

using Clock = std::chrono::steady_clock;

thread_local bool tCloseConnection = false;

std::chrono::milliseconds toMs(double seconds) {
  return std::chrono::milliseconds(static_cast<long long>(seconds * 1000.0));
}

void addressOf(socket_t sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  ip.clear();
  port = 0;
  if ((peer ? getpeername(sock, reinterpret_cast<sockaddr*>(&addr), &len)
            : getsockname(sock, reinterpret_cast<sockaddr*>(&addr), &len)) != 0)
    return;
  char buf[INET6_ADDRSTRLEN] = {};
  if (addr.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    inet_ntop(AF_INET, &a->sin_addr, buf, sizeof buf);
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    inet_ntop(AF_INET6, &a->sin6_addr, buf, sizeof buf);
    port = ntohs(a->sin6_port);
  }
  ip = buf;
}

// A buffered socket stream whose reads fail once the request's deadline has passed, and which
// notices the listener closing (stop()) within 100 ms.
class DeadlineStream final : public httplib::Stream {
public:
  DeadlineStream(socket_t sock, const std::atomic<socket_t>& listener, double writeTimeoutS)
      : sock_(sock), listener_(listener), writeTimeout_(toMs(writeTimeoutS)) {}

  void setDeadline(Clock::time_point d) { deadline_ = d; }
  bool buffered() const { return off_ < len_; }

  // Waits for `events` until `until`; false on timeout, error or (reading) server stop.
  bool wait(short events, Clock::time_point until) const {
    for (;;) {
      // A stopping server reads no more requests, but finishes writing the ones it answers.
      if (events == POLLIN && listener_ == INVALID_SOCKET) return false;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
      if (left.count() <= 0) return false;
      pollfd p{sock_, events, 0};
      const int r = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 100)));
      if (r > 0) return (p.revents & (events | POLLHUP | POLLERR)) != 0;
      if (r < 0 && errno != EINTR) return false;
    }
  }

  bool is_readable() const override { return buffered() || wait(POLLIN, deadline_); }
  bool is_writable() const override { return wait(POLLOUT, Clock::now() + writeTimeout_); }

  ssize_t read(char* ptr, size_t size) override {
    if (!buffered()) {
      if (!wait(POLLIN, deadline_)) return -1;
      const ssize_t n = recv(sock_, buf_, sizeof buf_, 0);
      if (n <= 0) return n;
      off_ = 0;
      len_ = static_cast<std::size_t>(n);
    }
    const std::size_t n = std::min(size, len_ - off_);
    std::memcpy(ptr, buf_ + off_, n);
    off_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    return send(sock_, ptr, size, MSG_NOSIGNAL);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { addressOf(sock_, true, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { addressOf(sock_, false, ip, port); }
  socket_t socket() const override { return sock_; }

private:
  socket_t sock_;
  const std::atomic<socket_t>& listener_;
  std::chrono::milliseconds writeTimeout_;
  Clock::time_point deadline_ = Clock::now();
  char buf_[4096];
  std::size_t off_ = 0, len_ = 0;
};

}  // namespace

void markCloseConnection() { tCloseConnection = true; }

// cpp-httplib's default socket options add SO_REUSEPORT, so a second daemon started on a port already
// in use bound it too and the kernel split the connections between the two: a render answered by one,
// its frame fetched from the other, 404 (seen 2026-12-04 with two radiantd on one port). SO_REUSEADDR
// alone still lets a restarted daemon bind over TIME_WAIT, and the second bind fails (HttpServer::bind).
BoundedServer::BoundedServer() {
  set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, reinterpret_cast<const void*>(&yes), sizeof(yes));
  });
}

bool BoundedServer::process_and_close_socket(socket_t sock) {
  const int one = 1;
  setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  DeadlineStream strm(sock, svr_sock_, timeouts_.writeS);
  bool ok = true;
  for (std::size_t count = keep_alive_max_count_; count > 0; --count) {
    // Idle: the next request must start within the keep-alive timeout.
    if (!strm.buffered() && !strm.wait(POLLIN, Clock::now() + toMs(timeouts_.keepAliveS))) break;
    // Then all of it (request line, headers, body) within the read timeout.
    strm.setDeadline(Clock::now() + toMs(timeouts_.readS));
    tCloseConnection = false;
    bool closed = false;
    ok = process_request(strm, count == 1 || tCloseConnection, closed, nullptr);
    if (!ok || closed || tCloseConnection) break;
  }
  tCloseConnection = false;
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ok;
}

ElasticPool::ElasticPool(std::size_t initialThreads, std::size_t maxThreads) : max_(std::max(maxThreads, std::size_t(1))) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < std::min(initialThreads, max_); ++i) threads_.emplace_back([this] { work(); });
}

ElasticPool::~ElasticPool() { shutdown(); }

void ElasticPool::enqueue(std::function<void()> fn) {
  std::lock_guard lock(mutex_);
  jobs_.push_back(std::move(fn));
  // Every worker busy: one more, up to the cap (beyond it, connections wait in the queue).
  if (idle_ < jobs_.size() && threads_.size() < max_) threads_.emplace_back([this] { work(); });
  cond_.notify_one();
}

void ElasticPool::shutdown() {
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    threads.swap(threads_);
  }
  cond_.notify_all();
  for (auto& t : threads) t.join();
}

std::size_t ElasticPool::threads() {
  std::lock_guard lock(mutex_);
  return threads_.size();
}

void ElasticPool::work() {
  for (;;) {
    std::function<void()> fn;
    {
      std::unique_lock lock(mutex_);
      ++idle_;
      cond_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
      --idle_;
      if (jobs_.empty()) return;  // stop_ and nothing left
      fn = std::move(jobs_.front());
      jobs_.pop_front();
    }
    fn();
  }
}

}  // namespace radiant::server
