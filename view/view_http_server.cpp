#include "view_http_server.h"

#include <httplib.h>
#include <sys/socket.h>

#include <chrono>
#include <thread>

namespace cvslam::view {
namespace {

// Worker threads beyond the event streams: the page, /state.json, and a 503 for the rest.
constexpr int kSpareWorkers = 4;

}  // namespace

ViewHttpServer::ViewHttpServer(ViewHttpOptions options, std::string page, DeltaFn delta)
    : o_(std::move(options)), page_(std::move(page)), delta_(std::move(delta)) {
  routes();
}

ViewHttpServer::ViewHttpServer(ViewHttpOptions options, std::string page, Json run)
    : o_(std::move(options)), page_(std::move(page)), run_(run.dump()) {
  routes();
}

ViewHttpServer::~ViewHttpServer() {
  stop();
}

void ViewHttpServer::routes() {
  server_ = std::make_unique<httplib::Server>();
  // SO_REUSEADDR only: cpp-httplib's default adds SO_REUSEPORT, with which a second viewer on
  // the same port would bind too and take half the connections instead of failing.
  server_->set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  const int workers = o_.max_clients + kSpareWorkers;
  server_->new_task_queue = [workers] {
    return new httplib::ThreadPool(static_cast<std::size_t>(workers));
  };
  const auto timeout = std::chrono::duration<double>(o_.write_timeout_s);
  server_->set_write_timeout(std::chrono::duration_cast<std::chrono::microseconds>(timeout));
  server_->Get("/", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(page_, "text/html; charset=utf-8");
  });
  server_->Get("/state.json", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    if (run_) {
      res.set_content(*run_, "application/json");
      return;
    }
    ViewCursor fresh;
    res.set_content(delta_(fresh).dump(), "application/json");
  });
  server_->Get("/events", [this](const httplib::Request&, httplib::Response& res) {
    if (run_) {
      res.status = 404;
      res.set_content("a finished run has no live events: GET /state.json\n", "text/plain");
      return;
    }
    if (clients_.fetch_add(1) >= o_.max_clients) {
      clients_.fetch_sub(1);
      res.status = 503;
      res.set_content("too many viewers\n", "text/plain");
      return;
    }
    ++clients_served_;
    res.set_header("Cache-Control", "no-store");
    auto cursor = std::make_shared<ViewCursor>();
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, cursor](std::size_t, httplib::DataSink& sink) {
          if (stopping_ || !sink.is_writable()) return false;
          // The delta is built under the node's lock; the write (which may block on a slow
          // client up to the write timeout) is outside it.
          const std::string event = "data: " + delta_(*cursor).dump() + "\n\n";
          if (!sink.write(event.data(), event.size())) return false;
          ++events_sent_;
          const auto until =
              std::chrono::steady_clock::now() + std::chrono::duration<double>(o_.push_period_s);
          while (!stopping_ && std::chrono::steady_clock::now() < until)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          return !stopping_.load();
        },
        [this](bool) { clients_.fetch_sub(1); });
  });
}

Status ViewHttpServer::bind() {
  if (o_.port == 0) {
    port_ = server_->bind_to_any_port(o_.host);
    if (port_ <= 0) return Status::Error("cannot bind " + o_.host + " to any port");
    return Status::Ok();
  }
  if (!server_->bind_to_port(o_.host, o_.port))
    return Status::Error("cannot bind " + o_.host + ":" + std::to_string(o_.port) +
                         " (port in use or address not local)");
  port_ = o_.port;
  return Status::Ok();
}

void ViewHttpServer::serve() {
  server_->listen_after_bind();
}

void ViewHttpServer::stop() {
  stopping_ = true;
  if (server_) server_->stop();
}

}  // namespace cvslam::view
