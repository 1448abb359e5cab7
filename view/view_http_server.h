#pragma once
// The HTTP side of cvslam_view (docs/view.md), on cpp-httplib (Debian's libcpp-httplib-dev):
//   GET /            the page (view/web/index.html, built into the program)
//   GET /state.json  the whole state now (live), or the whole finished run (--run)
//   GET /events      live: server-sent events, one JSON delta per push period
// Each /events client has its own cursor and its own worker thread: the bus and the other
// clients never wait on it. A client that does not read is cut off by the write timeout; a
// closed tab ends its stream at the next push. Clients beyond max_clients get 503.

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cvslam/core/status.h"
#include "cvslam/io/json_file.h"
#include "cvslam/view/team_view.h"

namespace httplib {
class Server;
}

namespace cvslam::view {

struct ViewHttpOptions {
  std::string host = "127.0.0.1";  ///< localhost only unless told otherwise
  int port = 8088;                 ///< 0: any free port (port() tells which)
  double push_period_s = 0.2;      ///< one delta per client every … (wall) [s]
  int max_clients = 4;             ///< simultaneous /events streams
  double write_timeout_s = 2.0;    ///< a client that takes longer to read is dropped [s]
};

class ViewHttpServer {
 public:
  /// Live: `delta` gives a client's next delta (ViewNode::delta).
  using DeltaFn = std::function<Json(ViewCursor&)>;
  ViewHttpServer(ViewHttpOptions options, std::string page, DeltaFn delta);
  /// Finished run: `/state.json` serves `run` and there is no /events stream.
  ViewHttpServer(ViewHttpOptions options, std::string page, Json run);
  ~ViewHttpServer();

  /// Binds host:port; fails with a clear message (port in use, bad address).
  Status bind();
  /// Serves until stop(); call after bind().
  void serve();
  void stop();
  int port() const { return port_; }
  int64_t eventsSent() const { return events_sent_; }
  int64_t clientsServed() const { return clients_served_; }

 private:
  void routes();

  ViewHttpOptions o_;
  std::string page_;
  DeltaFn delta_;
  std::optional<std::string> run_;
  std::unique_ptr<httplib::Server> server_;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<int> clients_{0};
  std::atomic<int64_t> events_sent_{0}, clients_served_{0};
};

}  // namespace cvslam::view
