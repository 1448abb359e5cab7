#pragma once
// A minimal W3C WebDriver client for the page tests: Debian's chromedriver drives Debian's
// headless Chromium (packages chromium, chromium-driver; scripts/setup.sh installs them). The
// page is a real browser's: its JavaScript runs, its EventSource stays open, and the test reads
// what it reports in the DOM (view/web/index.html, #report).

#include <httplib.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "cvslam/io/json_file.h"
#include "replay/process_util.h"

namespace cvslam::test {

class WebDriver {
 public:
  /// Starts chromedriver on `port` and a headless Chromium session with the window size given.
  WebDriver(int port, const std::string& log_prefix, int width = 1400, int height = 900)
      : driver_({"/usr/bin/chromedriver", "--port=" + std::to_string(port)}, log_prefix),
        http_("127.0.0.1", port) {
    http_.set_read_timeout(60, 0);
    for (int i = 0; i < 100 && !http_.Get("/status"); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const Json caps = {
        {"capabilities",
         {{"alwaysMatch",
           {{"browserName", "chrome"},
            {"goog:chromeOptions",
             {{"binary", "/usr/bin/chromium"},
              {"args",
               {"--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--disable-dev-shm-usage", "--hide-scrollbars",
                "--window-size=" + std::to_string(width) + "," + std::to_string(height)}}}}}}}}};
    const Json answer = post("/session", caps);
    if (answer.contains("value") && answer["value"].contains("sessionId"))
      session_ = answer["value"]["sessionId"].get<std::string>();
    else
      error_ = answer.dump();
  }
  ~WebDriver() {
    if (!session_.empty()) http_.Delete(("/session/" + session_).c_str());
  }
  bool ok() const { return !session_.empty(); }
  const std::string& error() const { return error_; }

  bool open(const std::string& url) {
    return post("/session/" + session_ + "/url", {{"url", url}}).contains("value");
  }
  /// Runs `script` (a function body) in the page; its return value.
  Json execute(const std::string& script) {
    const Json answer = post("/session/" + session_ + "/execute/sync",
                             {{"script", script}, {"args", Json::array()}});
    return answer.contains("value") ? answer["value"] : Json();
  }
  /// The page's #report data attributes (view/web/index.html), as strings.
  Json report() {
    return execute(
        "const r = document.getElementById('report'); return r ? Object.assign({}, r.dataset) : "
        "null;");
  }
  /// A PNG of the window, base64 as WebDriver gives it.
  std::string screenshotBase64() {
    auto res = http_.Get(("/session/" + session_ + "/screenshot").c_str());
    if (!res) return {};
    auto json = parseJson(res->body);
    return json.ok() && json->contains("value") ? (*json)["value"].get<std::string>() : "";
  }

 private:
  Json post(const std::string& path, const Json& body) {
    auto res = http_.Post(path.c_str(), body.dump(), "application/json");
    if (!res) return Json{{"error", "no answer from chromedriver"}};
    auto json = parseJson(res->body);
    return json.ok() ? *json : Json{{"error", res->body}};
  }

  Child driver_;
  httplib::Client http_;
  std::string session_, error_;
};

/// Decodes base64 (WebDriver screenshots).
inline std::string base64Decode(const std::string& in) {
  std::string out;
  int bits = 0, value = 0;
  for (char c : in) {
    int d;
    if (c >= 'A' && c <= 'Z')
      d = c - 'A';
    else if (c >= 'a' && c <= 'z')
      d = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      d = c - '0' + 52;
    else if (c == '+')
      d = 62;
    else if (c == '/')
      d = 63;
    else
      continue;
    value = (value << 6) | d;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((value >> bits) & 0xff));
    }
  }
  return out;
}

}  // namespace cvslam::test
