// cvslam_view — the team in a browser page (docs/view.md): a top view in the team frame with
// each UAV's estimated track, position and 2σ ellipse, the ground truth when published, the
// landmark maps, links while UAVs exchange landmarks (and to the ground station in CC), and
// per UAV strips of position σ, NEES, frame latency and bytes/s. Live from LCM, or a finished
// run folder with a time slider (--run). A thin shell: the model in common/view (TeamView,
// runViewJson), the bus in transport/ (ViewNode), HTTP in view_http_server.h.
//
//   cvslam_view                       live, http://127.0.0.1:8088/
//   cvslam_view --run runs/t3         a finished run

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include "cvslam/io/cli.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/process_shell.h"
#include "cvslam/lcm/view_node.h"
#include "cvslam/view/run_view.h"
#include "view_http_server.h"
#include "view_page.h"

namespace {

using cvslam::Status;

constexpr const char* kUsage =
    R"(usage: cvslam_view [--run DIR] [options]

The team in a browser page. Live: subscribes to the team's LCM channels (UAV<id>/POSE, /GT,
/MAP, /SHARED_REQ, /SHARED, /OBS, /GS_STATE, /FEATURES, /STEREO, TEAM/SUMMARY, GS/MAP) and
serves the page with updates as server-sent events. With --run: a finished run folder
(docs/run_format.md) played with a time slider, no LCM. Prints the page's URL.

options:
  --run DIR           show a finished run folder instead of the live team
  --port P            HTTP port (default 8088; 0: any free port, printed)
  --host ADDR         address to bind (default 127.0.0.1: this host only; 0.0.0.0: every
                      interface — anyone who reaches the host sees the team)
  --lcm-url URL       LCM provider (default udpm://239.255.76.67:7667?ttl=0)
  --auth-key FILE     the team key: accept only cooperation messages signed with it
  --config FILE       view options (default: config/view.yaml of the source tree)
  --max-agent-id N    directed channels are subscribed for UAV ids 1..N (default 16)
  --no-latency        do not subscribe to the sensor frames (no latency strip, less CPU)
  --duration S        exit after S seconds of wall time (default: until SIGINT/SIGTERM)
  --quiet             no periodic status line
  -h, --help          this text
)";

const cvslam::cli::ProcessShell shell("cvslam_view");
int fail(const std::string& message) {
  return shell.fail(message);
}

struct Args {
  std::string run, host = "127.0.0.1", url, config, auth_key;
  int port = 8088, max_agent_id = 16;
  double duration = 0.0;
  bool no_latency = false, quiet = false;
};

std::optional<int> parseArgs(int argc, char** argv, Args* a) {
  CLI::App app("the team in a browser page", "cvslam_view");
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--run", a->run);
  app.add_option("--port", a->port)
      ->check(cvslam::cli::numberValidator("PORT", "an integer in [0, 65535]", [](double x) {
        return x >= 0 && x <= 65535 && x == std::floor(x);
      }));
  app.add_option("--host", a->host);
  app.add_option("--lcm-url", a->url);
  app.add_option("--auth-key", a->auth_key);
  app.add_option("--config", a->config);
  app.add_option("--max-agent-id", a->max_agent_id)
      ->check(cvslam::cli::numberValidator("N", "an integer in [1, 1000]", [](double x) {
        return x >= 1 && x <= 1000 && x == std::floor(x);
      }));
  app.add_option("--duration", a->duration)->check(cvslam::cli::kPositive);
  app.add_flag("--no-latency", a->no_latency);
  app.add_flag("--quiet", a->quiet);
  if (auto exit_code = cvslam::cli::parse(app, argc, argv, kUsage)) return exit_code;
  if (!a->run.empty() && !a->url.empty()) return fail("--run and --lcm-url exclude each other");
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (auto exit_code = parseArgs(argc, argv, &args)) return *exit_code;
  const std::string config_path =
      args.config.empty() ? std::string(CVSLAM_CONFIG_DIR "/view.yaml") : args.config;
  auto root = cvslam::ConfigNode::loadFile(config_path);
  if (!root.ok()) return fail(root.status().message());
  cvslam::view::TeamViewOptions model;
  cvslam::view::ViewHttpOptions http;
  (void)model.load(root->child("view"));
  const cvslam::ConfigNode server = root->child("server");
  server.get("push_period_s", http.push_period_s);
  server.get("max_clients", http.max_clients);
  server.get("write_timeout_s", http.write_timeout_s);
  server.check(http.push_period_s > 0.0, "push_period_s", "must be > 0");
  server.check(http.max_clients >= 1, "max_clients", "must be >= 1");
  server.check(http.write_timeout_s > 0.0, "write_timeout_s", "must be > 0");
  if (Status s = root->finish(); !s.ok()) return fail(s.message());
  http.host = args.host;
  http.port = args.port;

  std::unique_ptr<cvslam::transport::ViewNode> node;
  std::unique_ptr<cvslam::view::ViewHttpServer> web;
  if (!args.run.empty()) {
    auto doc = cvslam::view::runViewJson(args.run, model);
    if (!doc.ok()) return fail(doc.status().message());
    web = std::make_unique<cvslam::view::ViewHttpServer>(http, cvslam::view::kViewPage,
                                                         std::move(*doc));
  } else {
    cvslam::transport::ViewNodeOptions o;
    if (!args.url.empty()) o.url = args.url;
    if (Status s = cvslam::transport::checkLcmUrl(o.url); !s.ok()) return fail(s.message());
    o.max_agent_id = args.max_agent_id;
    auto key = cvslam::transport::TeamKey::forOption(args.auth_key);
    if (!key.ok()) return fail(key.status().message());
    o.auth_key = *key;
    o.latency = !args.no_latency;
    o.view = model;
    auto created = cvslam::transport::ViewNode::create(o);
    if (!created.ok()) return fail(created.status().message());
    node = std::move(*created);
    cvslam::transport::ViewNode* n = node.get();
    web = std::make_unique<cvslam::view::ViewHttpServer>(
        http, cvslam::view::kViewPage, [n](cvslam::view::ViewCursor& c) { return n->delta(c); });
  }
  if (Status s = web->bind(); !s.ok()) return fail(s.message());
  if (node) {
    if (Status s = node->start(); !s.ok()) return fail(s.message());
  }
  shell.stopOnSignals();
  std::printf("cvslam_view: http://%s:%d/ (%s)\n",
              args.host == "0.0.0.0" ? "127.0.0.1" : args.host.c_str(), web->port(),
              args.run.empty() ? "live" : args.run.c_str());
  std::fflush(stdout);
  std::thread serving([&] { web->serve(); });
  const auto start = std::chrono::steady_clock::now();
  auto last_status = start;
  while (!shell.stopping()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto now = std::chrono::steady_clock::now();
    if (args.duration > 0 && std::chrono::duration<double>(now - start).count() >= args.duration)
      break;
    if (!args.quiet && node && now - last_status >= std::chrono::seconds(10)) {
      last_status = now;
      std::fprintf(stderr, "cvslam_view: %lld messages, %lld malformed, %lld viewers so far\n",
                   static_cast<long long>(node->messages()),
                   static_cast<long long>(node->malformed()),
                   static_cast<long long>(web->clientsServed()));
    }
  }
  web->stop();
  serving.join();
  if (node) node->stop();
  if (node)
    std::printf("cvslam_view: %lld messages, %lld malformed (dropped), %lld viewers, %lld events\n",
                static_cast<long long>(node->messages()), static_cast<long long>(node->malformed()),
                static_cast<long long>(web->clientsServed()),
                static_cast<long long>(web->eventsSent()));
  return 0;
}
