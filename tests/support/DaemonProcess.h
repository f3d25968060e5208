#pragma once
// Test support: a radiantd (or fake_radiantd) process on an ephemeral loopback port, started with
// fork/exec; the port is read from its first stdout line ("radiantd listening on http://127.0.0.1:PORT").
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>

namespace radiant::testing {

namespace fs = std::filesystem;

// A fresh scratch directory for one test (removed first if left over).
inline fs::path scratch(const std::string& name) {
  auto dir = fs::temp_directory_path() / ("radiant-daemon-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

struct ProcessRun {
  int code = -1;
  std::string out, err;
};

// Runs the radiant client at `clientPath` with ARGS (shell words) in `dir`, with RADIANT_SERVER=server;
// its stdout and stderr are kept apart.
inline ProcessRun runClient(const std::string& clientPath, const std::string& server, const std::string& args,
                            const fs::path& dir) {
  const fs::path out = dir / "client.out", err = dir / "client.err";
  const std::string cmd = "cd '" + dir.string() + "' && RADIANT_SERVER='" + server + "' '" + clientPath + "' " + args +
                          " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  return ProcessRun{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

// A daemon process started with fork/exec; the port is read from its first stdout line.
class Daemon {
public:
  Daemon(const std::string& exe, std::vector<std::string> args, const std::vector<std::string>& env = {},
         const fs::path& stderrFile = {}) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ == 0) {
      dup2(out[1], STDOUT_FILENO);
      // The daemon's log lines go to a file (or nowhere), not into the test's output.
      int fd = open(stderrFile.empty() ? "/dev/null" : stderrFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, STDERR_FILENO);
      close(out[0]);
      for (const auto& e : env) putenv(const_cast<char*>(e.c_str()));
      std::vector<char*> argv{const_cast<char*>(exe.c_str())};
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
    close(out[1]);
    out_ = out[0];
    // Read the first line: "radiantd listening on http://127.0.0.1:PORT".
    std::string line;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (line.find('\n') == std::string::npos && std::chrono::steady_clock::now() < end) {
      pollfd p{out_, POLLIN, 0};
      if (poll(&p, 1, 100) > 0) {
        char buf[256];
        ssize_t n = read(out_, buf, sizeof buf);
        if (n <= 0) break;
        line.append(buf, static_cast<std::size_t>(n));
      }
    }
    firstLine_ = line.substr(0, line.find('\n'));
    std::smatch m;
    if (std::regex_match(firstLine_, m, std::regex(R"(radiantd listening on http://127\.0\.0\.1:(\d+))")))
      port_ = std::stoi(m[1]);
  }
  ~Daemon() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (out_ >= 0) close(out_);
  }
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  const std::string& firstLine() const { return firstLine_; }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(120, 0);
    return c;
  }
  void signal(int sig) { kill(pid_, sig); }
  // Exit code, or -1 when it did not exit within `timeout`, or 128+signal when killed by one.
  int wait(std::chrono::seconds timeout = std::chrono::seconds(60)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }
  bool waitReady(std::chrono::seconds timeout) {
    auto c = client();
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      auto r = c.Get("/v1/ready");
      if (r && r->status == 200) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

private:
  pid_t pid_ = -1;
  int out_ = -1;
  int port_ = 0;
  bool exited_ = false;
  std::string firstLine_;
};


}  // namespace radiant::testing
