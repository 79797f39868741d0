#pragma once
// The studio's in-process test server (test_studio_api.cpp, test_studio_socket.cpp): a Session of a
// small model, its Api and a Server on a free port of 127.0.0.1, driven by httplib::Client.
#include "studio/json.hpp"
#include "studio/server.hpp"

#include <httplib.h>
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace vitri::studio::testing {

/// 25 constraints: the center of an ellipsoid (value -0.5), 18 points of its surface, 6 outside (+1).
inline Constraints small_model() {
  Constraints c;
  c.add({0, 0, 0}, -0.5);
  const double pi = 3.14159265358979323846, golden = pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < 18; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 18.0, r = std::sqrt(1.0 - z * z), phi = golden * i;
    c.add({r * std::cos(phi), 0.8 * r * std::sin(phi), 0.6 * z}, 0.0);
  }
  for (int k = 0; k < 3; ++k)
    for (const double s : {-2.0, 2.0}) c.add({k == 0 ? s : 0.0, k == 1 ? s : 0.0, k == 2 ? s : 0.0}, 1.0);
  return c;
}

inline SessionOptions fast_options() {
  SessionOptions o;
  o.precision = 0.06;
  o.coarse_levels = 1;
  return o;
}

/// The server of one test, serving on its own thread until destroyed.
struct Running {
  Session session;
  Api api;
  Server server;
  std::thread thread;
  httplib::Client client;

  explicit Running(std::size_t max_body = 1u << 20)
      : session(small_model(), "small", fast_options()),
        api(session),
        server(api, options(max_body)),
        thread((server.bind(), [this] { server.run(); })),
        client("127.0.0.1", server.port()) {
    client.set_read_timeout(120, 0);
    for (int i = 0; i < 200 && !client.Get("/api/stats"); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ~Running() {
    server.stop();
    thread.join();
  }
  static ServerOptions options(std::size_t max_body) {
    ServerOptions o;
    o.port = 0;
    o.max_body = max_body;
    o.web_dir = VITRI_STUDIO_WEB_DIR;
    o.three_dir = "/nonexistent-three";
    return o;
  }

  /// Status and parsed JSON body of a request.
  Json get(const std::string& path, int status = 200) { return check(client.Get(path.c_str()), status); }
  Json post(const std::string& path, const std::string& body, int status = 200) {
    return check(client.Post(path.c_str(), body, "application/json"), status);
  }
  static Json check(const httplib::Result& r, int status) {
    REQUIRE(r);
    INFO("body: " << r->body);
    CHECK(r->status == status);
    CHECK(r->get_header_value("Content-Type") == "application/json");
    return Json::parse(r->body);
  }
  /// The model as the API shows it (constraints, mesh size, undo depth), without timings.
  std::string fingerprint() {
    const Json s = get("/api/state");
    std::string out = Json(s.find("constraint_list")->as_array("")).dump();
    for (const char* k : {"constraints", "vertices", "triangles", "undo", "redo", "revision", "precision",
                          "constraint_version"})
      out += std::string(" ") + k + "=" + s.find(k)->dump();
    return out;
  }
};

}  // namespace vitri::studio::testing
