#pragma once
// Headless Chromium for the browser tests: a child process started with its output in a log, and the DevTools
// protocol spoken over a pipe (--remote-debugging-pipe), one page session at a time.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace palpate::test {

using Clock = std::chrono::steady_clock;

// Starts argv[0] (looked up on PATH) with stdout and stderr into log_path; fd_in / fd_out (when >= 0) become the
// child's fds 3 and 4. Returns the pid, -1 on failure.
inline pid_t spawn(const std::vector<std::string>& argv, const std::string& log_path, int fd_in = -1, int fd_out = -1) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  ::dup2(log, 1);
  ::dup2(log, 2);
  // moved out of the way first, so that dup2 onto 3 and 4 cannot close one of them
  const int in = fd_in >= 0 ? ::fcntl(fd_in, F_DUPFD, 10) : -1;
  const int out = fd_out >= 0 ? ::fcntl(fd_out, F_DUPFD, 10) : -1;
  if (in >= 0) ::dup2(in, 3);
  if (out >= 0) ::dup2(out, 4);
  ::execvp(args[0], args.data());
  std::_Exit(127);
}

// Headless Chromium driven through the DevTools protocol on a pipe (JSON messages ended by a NUL byte).
class Browser {
 public:
  /// The page session commands go to (attach() sets it).
  void use(const std::string& session) { session_ = session; }
  /// The page session in use.
  const std::string& session() const { return session_; }

  bool launch(const std::string& url, const std::string& dir) {
    int to[2], from[2];
    if (::pipe2(to, O_CLOEXEC) != 0 || ::pipe2(from, O_CLOEXEC) != 0) return false;
    pid_ = spawn({"chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
                  "--no-first-run", "--window-size=1200,1000",
                  // a page in a window behind another keeps its timers (the device page sends at 66 Hz)
                  "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
                  "--disable-backgrounding-occluded-windows", "--user-data-dir=" + dir + "/profile", url},
                 dir + "/chromium.log", to[0], from[1]);
    ::close(to[0]);
    ::close(from[1]);
    write_fd_ = to[1];
    read_fd_ = from[0];
    return pid_ > 0;
  }

  ~Browser() {
    if (pid_ <= 0) return;
    call("Browser.close", nlohmann::json::object(), false, 5);
    for (int i = 0; i < 100; ++i) {
      if (::waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(write_fd_);
    ::close(read_fd_);
  }

  // a command's result (the "result" object), or null after timeout_s or on an error reply
  nlohmann::json call(const std::string& method, const nlohmann::json& params, bool on_page, int timeout_s = 30) {
    const int id = next_id_++;
    nlohmann::json msg = {{"id", id}, {"method", method}, {"params", params}};
    if (on_page) msg["sessionId"] = session_;
    const std::string text = msg.dump() + std::string(1, '\0');
    if (::write(write_fd_, text.data(), text.size()) != static_cast<ssize_t>(text.size())) return nullptr;
    const auto end = Clock::now() + std::chrono::seconds(timeout_s);
    for (;;) {
      for (std::size_t z; (z = buf_.find('\0')) != std::string::npos;) {
        const auto reply = nlohmann::json::parse(buf_.substr(0, z), nullptr, false);
        buf_.erase(0, z + 1);
        if (!reply.is_discarded() && reply.value("id", -1) == id)
          return reply.contains("result") ? reply["result"] : nlohmann::json(nullptr);
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()).count();
      if (left <= 0) return nullptr;
      pollfd p{read_fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char chunk[65536];
      const ssize_t n = ::read(read_fd_, chunk, sizeof chunk);
      if (n <= 0) return nullptr;
      buf_.append(chunk, static_cast<std::size_t>(n));
    }
  }

  // attaches to the page showing `url`
  bool attach(const std::string& url) {
    const auto end = Clock::now() + std::chrono::seconds(60);
    while (Clock::now() < end) {
      const auto targets = call("Target.getTargets", nlohmann::json::object(), false);
      if (targets.is_object())
        for (const auto& t : targets["targetInfos"])
          if (t.value("type", "") == "page" && t.value("url", "") == url) {
            return attach_target(t["targetId"].get<std::string>());
          }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return false;
  }

  // attaches to a target by its id (its session becomes the one in use)
  bool attach_target(const std::string& target) {
    const auto a = call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}}, false);
    if (!a.is_object()) return false;
    session_ = a.value("sessionId", "");
    target_ = target;
    return !session_.empty();
  }

  // opens `url` in a new page and attaches to it
  bool open_page(const std::string& url) {
    const auto t = call("Target.createTarget", {{"url", url}, {"newWindow", true}}, false);
    return t.is_object() && attach_target(t.value("targetId", ""));
  }

  /// The target (page) attached last.
  const std::string& target() const { return target_; }

  // the value of a JavaScript expression in the page (null when it failed)
  nlohmann::json eval(const std::string& expression) {
    const auto r = call("Runtime.evaluate", {{"expression", expression}, {"returnByValue", true}}, true);
    if (!r.is_object() || r.contains("exceptionDetails") || !r["result"].contains("value")) return nullptr;
    return r["result"]["value"];
  }

 private:
  pid_t pid_ = -1;
  int write_fd_ = -1, read_fd_ = -1;
  int next_id_ = 1;
  std::string session_;
  std::string target_;
  std::string buf_;
};

}  // namespace palpate::test
