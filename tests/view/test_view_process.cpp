// cvslam_view as a real process (docs/view.md): a 3-UAV lockstep team watched in headless
// Chromium through WebDriver — three tracks, the agents' own landmark counts, links drawn when
// and between whom coop.csv records an exchange; malformed messages counted and ignored; a
// stalled or closed client never holds the process; bound to localhost; bad command lines.
// LCM ports 27850–27859, HTTP ports 18150–18169.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "agent/agent_test_util.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/message_types.h"
#include "webdriver.h"

namespace cvslam {
namespace {

using namespace std::chrono_literals;

std::string team3() {
  return std::string(CVSLAM_SOURCE_DIR) + "/config/scenarios/team3_aerial.yaml";
}

/// GET http://127.0.0.1:port/path (empty on failure).
std::string httpGet(int port, const std::string& path) {
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(5, 0);
  auto res = c.Get(path.c_str());
  return res && res->status == 200 ? res->body : std::string();
}

/// cvslam_view live on LCM `url`, HTTP `port`, logging to tmp/view.{out,err}.
std::unique_ptr<test::Child> liveView(const test::TempFolder& tmp, const std::string& url,
                                      int port) {
  return std::make_unique<test::Child>(
      std::vector<std::string>{CVSLAM_VIEW_EXE, "--lcm-url", url, "--port", std::to_string(port),
                               "--quiet"},
      tmp / "view");
}

/// Waits until the view answers on its port.
bool waitForView(int port) {
  for (int i = 0; i < 100; ++i) {
    if (!httpGet(port, "/state.json").empty()) return true;
    std::this_thread::sleep_for(100ms);
  }
  return false;
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

/// Rows of a landmarks.csv (the agent's map at the end: active and archived).
std::size_t landmarkRows(const std::string& path) {
  std::ifstream f(path);
  std::size_t n = 0;
  for (std::string line; std::getline(f, line);)
    if (!line.empty() && line[0] != '#') ++n;
  return n > 0 ? n - 1 : 0;
}

/// "from>to@t" of every exchange (request or landmarks sent) agent `from` records in its
/// coop.csv, one per row.
std::multiset<std::string> exchangesOf(const std::string& run, int from) {
  std::multiset<std::string> out;
  std::ifstream f(run + "/agent_" + std::to_string(from) + "/coop.csv");
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    const auto cols = split(line, ',');
    if (cols.size() < 3 || (cols[1] != "request_sent" && cols[1] != "shared_sent")) continue;
    out.insert(std::to_string(from) + ">" + cols[2] + "@" + cols[0]);
  }
  return out;
}

/// Every link the page reports drawing ("from>to@t"), added to `drawn`; the page's report.
Json collectLinks(test::WebDriver& browser, std::set<std::string>& drawn) {
  const Json r = browser.report();
  if (r.is_object() && r.contains("linkList"))
    for (const std::string& l : split(r["linkList"].get<std::string>(), ';')) drawn.insert(l);
  return r;
}

/// The links the page drew while `running` ran, polled every 200 ms.
std::set<std::string> linksDrawnWhileRunning(test::WebDriver& browser, test::Child& running) {
  std::set<std::string> drawn;
  while (!running.exited()) {
    collectLinks(browser, drawn);
    std::this_thread::sleep_for(200ms);
  }
  return drawn;
}

TEST(ViewProcess, ThreeUavLockstepTeamInHeadlessChromium) {
  test::TempFolder tmp;
  const std::string url = test::agentUrl(27850);
  const int http = 18150;
  const auto view = liveView(tmp, url, http);
  ASSERT_TRUE(waitForView(http)) << view->err();
  test::WebDriver browser(18151, tmp / "chromedriver");
  ASSERT_TRUE(browser.ok()) << browser.error();
  ASSERT_TRUE(browser.open("http://127.0.0.1:" + std::to_string(http) + "/"));
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2, 3})
    agents.push_back(std::make_unique<test::Child>(
        test::agentArgs(id, team3(), url, tmp / "run", "dc"), tmp / ("a" + std::to_string(id))));
  test::Child replay(
      {CVSLAM_REPLAY_EXE, "--scenario", team3(), "--sensing", "features", "--lockstep",
       "--lockstep-timeout", "20", "--duration", "20", "--lcm-url", url, "--quiet"},
      tmp / "replay");
  // While the team flies: every link the page draws, as it draws it.
  std::set<std::string> drawn = linksDrawnWhileRunning(browser, replay);
  EXPECT_EQ(replay.wait(1s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(60s), 0) << a->err();
  std::this_thread::sleep_for(1s);  // the last push reaches the page
  const Json report = collectLinks(browser, drawn);
  ASSERT_TRUE(report.is_object()) << report.dump();
  EXPECT_EQ(report["tracks"], "3");
  EXPECT_EQ(report["agents"], "1,2,3");
  EXPECT_EQ(report["malformed"], "0");
  // Landmark counts: the page's (from each agent's last POSE) are the agent's own final map.
  for (const std::string& entry : split(report["landmarks"].get<std::string>(), ';')) {
    const int id = std::stoi(entry.substr(0, entry.find(':')));
    const auto counts = split(entry.substr(entry.find(':') + 1), '/');
    ASSERT_EQ(counts.size(), 2u) << entry;
    const std::size_t own =
        landmarkRows(tmp / ("run/agent_" + std::to_string(id) + "/landmarks.csv"));
    EXPECT_GT(own, 0u);
    EXPECT_EQ(std::stoul(counts[0]) + std::stoul(counts[1]), own) << "UAV" << id;
  }
  // Every link drawn is an exchange its sender's coop.csv records, at that time and with that
  // peer; and the team did exchange while the page watched.
  std::set<std::string> recorded;
  for (int id : {1, 2, 3})
    for (const std::string& e : exchangesOf(tmp / "run", id)) recorded.insert(e);
  ASSERT_FALSE(recorded.empty()) << "no exchange in coop.csv: the test shows nothing";
  EXPECT_FALSE(drawn.empty()) << "the page drew no link";
  for (const std::string& link : drawn) EXPECT_EQ(recorded.count(link), 1u) << link;
  std::printf("[ view ] %zu links drawn of %zu exchanges recorded; landmarks %s\n", drawn.size(),
              recorded.size(), report["landmarks"].get<std::string>().c_str());
  // The page as it looked (a test artefact; docs/view_team3.png is made the same way).
  const std::string png = test::base64Decode(browser.screenshotBase64());
  EXPECT_GT(png.size(), 10000u);
  std::ofstream(std::string(CVSLAM_BINARY_DIR) + "/view_team3_test.png", std::ios::binary) << png;
}

TEST(ViewProcess, CentralisedTeamShowsTheGroundStation) {
  test::TempFolder tmp;
  const std::string url = test::agentUrl(27855);
  const int http = 18158;
  const auto view = liveView(tmp, url, http);
  ASSERT_TRUE(waitForView(http)) << view->err();
  test::WebDriver browser(18159, tmp / "chromedriver");
  ASSERT_TRUE(browser.ok()) << browser.error();
  ASSERT_TRUE(browser.open("http://127.0.0.1:" + std::to_string(http) + "/"));
  const std::string scenario = test::coopPair();
  test::Child gs({CVSLAM_GS_EXE, "--agents", "1,2", "--scenario", scenario, "--lcm-url", url,
                  "--out", tmp / "run", "--idle-exit", "3"},
                 tmp / "gs");
  std::vector<std::unique_ptr<test::Child>> agents;
  for (int id : {1, 2})
    agents.push_back(std::make_unique<test::Child>(
        test::agentArgs(id, scenario, url, tmp / "run", "cc"), tmp / ("a" + std::to_string(id))));
  test::Child replay(
      {CVSLAM_REPLAY_EXE, "--scenario", scenario, "--sensing", "features", "--lockstep",
       "--participants", "1,2,0", "--lockstep-timeout", "30", "--lcm-url", url, "--quiet"},
      tmp / "replay");
  const std::set<std::string> drawn = linksDrawnWhileRunning(browser, replay);
  EXPECT_EQ(replay.wait(1s), 0) << replay.err();
  for (auto& a : agents) EXPECT_EQ(a->wait(30s), 0) << a->err();
  EXPECT_EQ(gs.wait(30s), 0) << gs.err();
  const Json r = browser.report();
  EXPECT_EQ(r["tracks"], "2");
  EXPECT_NE(r["jointMapPoints"], "0") << r.dump();
  // Observation batches drawn as links from each UAV to the ground station (id 0).
  for (const char* uav : {"1>0@", "2>0@"}) {
    EXPECT_TRUE(std::any_of(drawn.begin(), drawn.end(), [&](const std::string& l) {
      return l.rfind(uav, 0) == 0;
    })) << uav;
  }
  // The ground station's estimate of each UAV is in the state the page gets.
  auto state = parseJson(httpGet(http, "/state.json"));
  ASSERT_TRUE(state.ok());
  for (const char* id : {"1", "2"}) {
    EXPECT_EQ((*state)["agents"][id]["mode"], "cc");
    EXPECT_TRUE((*state)["agents"][id].contains("gs")) << id;
  }
}

TEST(ViewProcess, MalformedMessagesAreCountedAndIgnored) {
  test::TempFolder tmp;
  const std::string url = test::agentUrl(27851);
  const int http = 18152;
  const auto view = liveView(tmp, url, http);
  ASSERT_TRUE(waitForView(http)) << view->err();
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  // Garbage, a truncated POSE, a POSE with the wrong fingerprint: 3 malformed messages.
  cvslam::agent_state_t pose{};
  pose.header.agent_id = 1;
  pose.header.utime = 1000000;
  pose.filter = "ekf";
  pose.state.assign(9, 0.0);
  pose.covariance.assign(81, 0.0);
  for (int i = 0; i < 9; ++i) pose.covariance[static_cast<std::size_t>(i * 10)] = 0.01;
  auto good = transport::encodeMessage(pose);
  ASSERT_TRUE(good.ok());
  const std::string garbage = "not an LCM message at all";
  ASSERT_TRUE((*bus)->publishRaw("UAV1/POSE", garbage.data(), garbage.size()).ok());
  ASSERT_TRUE((*bus)->publishRaw("UAV1/POSE", good->data(), good->size() / 2).ok());
  std::vector<uint8_t> wrong = *good;
  wrong[0] ^= 0xff;
  ASSERT_TRUE((*bus)->publishRaw("UAV1/POSE", wrong.data(), wrong.size()).ok());
  // A non-finite map: refused by validation.
  cvslam::agent_map_t map{};
  map.header.agent_id = 1;
  map.id = {1};
  map.position = {{std::nanf(""), 0.0f, 0.0f}};
  map.position_std = {0.1f};
  map.active = {1};
  map.num_landmarks = 1;
  std::vector<uint8_t> bad_map(static_cast<std::size_t>(map.getEncodedSize()));
  map.encode(bad_map.data(), 0, static_cast<int>(bad_map.size()));
  ASSERT_TRUE((*bus)->publishRaw("UAV1/MAP", bad_map.data(), bad_map.size()).ok());
  // Then a valid POSE: shown.
  ASSERT_TRUE((*bus)->publish("UAV1/POSE", pose).ok());
  Json state;
  for (int i = 0; i < 50; ++i) {
    auto parsed = parseJson(httpGet(http, "/state.json"));
    if (parsed.ok()) state = *parsed;
    if (state.contains("agents") && state["agents"].contains("1")) break;
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_TRUE(state.contains("agents") && state["agents"].contains("1")) << state.dump();
  EXPECT_EQ(state["malformed"], 4) << state.dump();
  EXPECT_EQ(state["malformed_by_channel"]["UAV[0-9]+/POSE"], 3) << state.dump();
  EXPECT_EQ(state["agents"]["1"]["samples"].size(), 1u);
  EXPECT_TRUE(state["agents"]["1"]["map"]["points"].empty());
}

TEST(ViewProcess, StalledAndClosedClientsDoNotHoldTheProcess) {
  test::TempFolder tmp;
  const std::string url = test::agentUrl(27852);
  const int http = 18153;
  const auto view = liveView(tmp, url, http);
  ASSERT_TRUE(waitForView(http)) << view->err();
  // A client that asks for the event stream and never reads, with a tiny receive buffer.
  const int stalled = ::socket(AF_INET, SOCK_STREAM, 0);
  const int small = 1024;
  ::setsockopt(stalled, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(http));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(stalled, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request = "GET /events HTTP/1.1\r\nHost: x\r\n\r\n";
  ASSERT_GT(::send(stalled, request.data(), request.size(), 0), 0);
  // Clients that open the stream and go away at once.
  for (int i = 0; i < 6; ++i) {
    httplib::Client c("127.0.0.1", http);
    (void)c.Get("/events", [](const char*, std::size_t) { return false; });
  }
  // Meanwhile a UAV publishes 2000 estimates, each with a growing track.
  transport::BusOptions o;
  o.url = url;
  auto bus = transport::LcmBus::create(o);
  ASSERT_TRUE(bus.ok());
  cvslam::agent_state_t pose{};
  pose.header.agent_id = 2;
  pose.filter = "ekf";
  pose.covariance.assign(81, 0.0);
  for (int i = 0; i < 9; ++i) pose.covariance[static_cast<std::size_t>(i * 10)] = 0.01;
  constexpr int kPoses = 2000;
  for (int k = 0; k < kPoses; ++k) {
    pose.header.utime = 50000LL * k;
    pose.state.assign(9, 0.0);
    pose.state[0] = 0.1 * k;
    ASSERT_TRUE((*bus)->publish("UAV2/POSE", pose).ok());
    if (k % 200 == 0) std::this_thread::sleep_for(5ms);
  }
  // Every estimate was taken, and a new viewer is served promptly.
  Json state;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 50; ++i) {
    auto parsed = parseJson(httpGet(http, "/state.json"));
    if (parsed.ok()) state = *parsed;
    if (state.value("messages", 0) >= kPoses) break;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(state.value("messages", 0), kPoses) << state.dump().substr(0, 300);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 3.0);
  // The closed clients' places are free again within a few pushes (a closed socket shows at
  // the next write), so a new viewer gets its stream.
  std::string events;
  for (int i = 0; i < 30 && events.rfind("data: {", 0) != 0; ++i) {
    httplib::Client c("127.0.0.1", http);
    c.set_read_timeout(1, 0);
    events.clear();
    (void)c.Get("/events", [&](const char* data, std::size_t n) {
      events.append(data, n);
      return events.find("\n\n") == std::string::npos;  // one event is enough
    });
    if (events.rfind("data: {", 0) != 0) std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(events.rfind("data: {", 0), 0u) << events.substr(0, 100);
  ::close(stalled);
}

TEST(ViewProcess, FinishedRunFolderPlaysWithATimeSlider) {
  test::TempFolder tmp;
  std::string err;
  ASSERT_EQ(test::run({CVSLAM_RUN_EXE, "--scenario", test::coopPair(), "--mode", "dc", "--sensing",
                       "features", "--out", tmp / "run", "--quiet"},
                      tmp / "cvslam_run", nullptr, &err),
            0)
      << err;
  const int http = 18156;
  test::Child view({CVSLAM_VIEW_EXE, "--run", tmp / "run", "--port", std::to_string(http)},
                   tmp / "view");
  ASSERT_TRUE(waitForView(http)) << view.err();
  auto doc = parseJson(httpGet(http, "/state.json"));
  ASSERT_TRUE(doc.ok());
  EXPECT_EQ((*doc)["live"], false);
  EXPECT_LT((*doc)["t0"].get<double>(), (*doc)["t1"].get<double>());
  std::size_t exchanges = 0;
  for (int id : {1, 2}) {
    const Json& a = (*doc)["agents"][std::to_string(id)];
    const std::string dir = tmp / ("run/agent_" + std::to_string(id));
    EXPECT_EQ(a["landmarks_active"].get<std::size_t>() + a["landmarks_archived"].get<std::size_t>(),
              landmarkRows(dir + "/landmarks.csv"));
    EXPECT_EQ(a["map"]["points"].size(), landmarkRows(dir + "/landmarks.csv"));
    EXPECT_GT(a["samples"].size(), 10u);
    EXPECT_GT(a["truth"].size(), 10u);
    // NEES wherever truth was at hand.
    std::size_t with_nees = 0;
    for (const Json& s : a["samples"]) with_nees += s[9].is_number() ? 1 : 0;
    EXPECT_GT(with_nees, a["samples"].size() / 2);
    exchanges += exchangesOf(tmp / "run", id).size();
  }
  EXPECT_GT(exchanges, 0u);
  EXPECT_EQ((*doc)["links"].size(), exchanges);
  EXPECT_TRUE(httpGet(http, "/events").empty());  // no live stream for a finished run
  // In the browser: two tracks at the end of the slider, links drawn somewhere along it.
  test::WebDriver browser(18157, tmp / "chromedriver");
  ASSERT_TRUE(browser.ok()) << browser.error();
  ASSERT_TRUE(browser.open("http://127.0.0.1:" + std::to_string(http) + "/"));
  Json r;
  for (int i = 0; i < 50 && !(r.is_object() && r.value("events", "0") != "0"); ++i) {
    r = browser.report();
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(r["live"], "false");
  EXPECT_EQ(r["tracks"], "2");
  const Json t_link = (*doc)["links"][0][0];
  browser.execute("const s = document.getElementById('slider'); s.value = " + t_link.dump() +
                  "; s.dispatchEvent(new Event('input'));");
  std::this_thread::sleep_for(300ms);
  r = browser.report();
  EXPECT_NE(r["linksDrawn"], "0") << r.dump();
}

TEST(ViewProcess, BindsToLocalhostByDefault) {
  test::TempFolder tmp;
  const int http = 18154;
  const auto view = liveView(tmp, test::agentUrl(27853), http);
  ASSERT_TRUE(waitForView(http)) << view->err();
  // /proc/net/tcp: the listening socket's local address is 127.0.0.1 (0100007F).
  std::ifstream tcp("/proc/net/tcp");
  char port_hex[8];
  std::snprintf(port_hex, sizeof port_hex, "%04X", http);
  bool found = false;
  for (std::string line; std::getline(tcp, line);) {
    if (line.find(std::string(":") + port_hex + " ") == std::string::npos) continue;
    if (line.find(" 0A ") == std::string::npos) continue;  // LISTEN
    found = true;
    EXPECT_NE(line.find("0100007F:" + std::string(port_hex)), std::string::npos) << line;
  }
  EXPECT_TRUE(found);
}

TEST(ViewProcess, BadCommandLinesGiveOneLineAndStatus2) {
  test::TempFolder tmp;
  const std::vector<std::vector<std::string>> bad = {
      {"--run", tmp / "no_such_run"},
      {"--port", "70000"},
      {"--port", "abc"},
      {"--lcm-url", "bogus://x"},
      {"--config", tmp / "missing.yaml"},
      {"--max-agent-id", "0"},
      {"--run", tmp.path(), "--lcm-url", "udpm://239.255.76.67:7667"}};
  int k = 0;
  for (const auto& args : bad) {
    std::vector<std::string> full = {CVSLAM_VIEW_EXE};
    full.insert(full.end(), args.begin(), args.end());
    std::string err;
    EXPECT_EQ(test::run(full, tmp / ("bad" + std::to_string(k++)), nullptr, &err), 2) << args[0];
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  // A port already taken.
  test::Child first(
      {CVSLAM_VIEW_EXE, "--lcm-url", test::agentUrl(27854), "--port", "18155", "--quiet"},
      tmp / "first");
  ASSERT_TRUE(waitForView(18155));
  std::string err;
  EXPECT_EQ(test::run({CVSLAM_VIEW_EXE, "--lcm-url", test::agentUrl(27854), "--port", "18155"},
                      tmp / "second", nullptr, &err),
            2);
  EXPECT_NE(err.find("cannot bind"), std::string::npos) << err;
}

}  // namespace
}  // namespace cvslam
