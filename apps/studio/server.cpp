// HTTP transport of the studio: cpp-httplib in, Api out. Every route goes through Api::handle (which
// never throws); transport errors (bad HTTP, payload over the limit) get a JSON body too.
#include "server.hpp"

#include "socket.hpp"

#include "vitri/core/error.hpp"

#include <httplib.h>

#include <sys/socket.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace vitri::studio {
namespace {

void answer(httplib::Response& res, const ApiResponse& r) {
  res.status = r.status;
  res.set_header("Cache-Control", "no-store");
  if (!r.download.empty())
    res.set_header("Content-Disposition", "attachment; filename=\"" + r.download + "\"");
  if (r.server_ms >= 0) {  // the page separates server time from transfer (docs/studio.md)
    char timing[64];
    std::snprintf(timing, sizeof timing, "app;dur=%.3f", r.server_ms);
    res.set_header("Server-Timing", timing);
  }
  res.set_content(r.body, r.content_type.c_str());
}

bool read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  out = s.str();
  return true;
}

}  // namespace

std::vector<StaticFile> static_files(const ServerOptions& o) {
  const char* js = "application/javascript; charset=utf-8";
  return {{"/", o.web_dir + "/index.html", "text/html; charset=utf-8"},
          {"/index.html", o.web_dir + "/index.html", "text/html; charset=utf-8"},
          {"/studio.js", o.web_dir + "/studio.js", js},
          {"/studio_buffers.js", o.web_dir + "/studio_buffers.js", js},
          {"/studio_bench.js", o.web_dir + "/studio_bench.js", js},
          {"/studio.css", o.web_dir + "/studio.css", "text/css; charset=utf-8"},
          {"/three/three.min.js", o.three_dir + "/build/three.min.js", js},
          {"/three/OrbitControls.js", o.three_dir + "/examples/js/controls/OrbitControls.js", js}};
}

struct Server::Impl {
  httplib::Server http;
  std::unique_ptr<SocketServer> socket;
};

Server::Server(Api& api, const ServerOptions& options)
    : api_(api), impl_(std::make_unique<Impl>()), options_(options) {
  httplib::Server& http = impl_->http;
  http.set_payload_max_length(options.max_body);
  // SO_REUSEADDR only: cpp-httplib's default also sets SO_REUSEPORT, with which a second studio on the
  // same port binds too and the two share the requests.
  http.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  http.set_tcp_nodelay(true);  // small responses go out at once (Nagle + delayed ACK cost ~40 ms each)
  const auto to_api = [this, &api](const httplib::Request& req, httplib::Response& res) {
    // A page of another site (a cross-site form or fetch, DNS rebinding) may not edit or read the model.
    if (!origin_allowed(req.get_header_value("Origin"), options_.host, port_, req.get_header_value("Host")))
      return answer(res, error_response(403, "a page of another origin may not use the studio: " +
                                                 req.get_header_value("Origin")));
    ApiRequest r;
    r.method = req.method;
    r.path = req.path;
    for (const auto& [k, v] : req.params) r.params.emplace(k, v);  // the first of repeated keys
    r.body = req.body;
    answer(res, api.handle(r));
  };
  const auto files = static_files(options);
  const auto serve = [files, to_api](const httplib::Request& req, httplib::Response& res) {
    if (Api::is_api_path(req.path)) return to_api(req, res);
    for (const StaticFile& f : files) {
      if (f.url != req.path) continue;
      std::string body;
      if (!read_file(f.path, body))
        return answer(res, error_response(500, "studio file missing: " + f.path + " (see docs/studio.md)"));
      res.set_content(body, f.content_type.c_str());
      return;
    }
    answer(res, error_response(404, "not found: " + req.path));
  };
  http.Get(".*", serve);
  http.Post(".*", serve);
  http.Put(".*", to_api);
  http.Delete(".*", to_api);
  http.Patch(".*", to_api);
  http.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    const std::string what = res.status == 413 ? "request body too large" : "bad request";
    answer(res, error_response(res.status, what + " (HTTP " + std::to_string(res.status) + ")"));
  });
}

Server::~Server() {
  stop();
}

int Server::bind() {
  if (options_.port == 0) {
    port_ = impl_->http.bind_to_any_port(options_.host);
    if (port_ <= 0) throw Error("studio: cannot bind " + options_.host);
  } else {
    if (!impl_->http.bind_to_port(options_.host, options_.port))
      throw Error("studio: cannot bind " + options_.host + ":" + std::to_string(options_.port) +
                  " (in use? try --port 0 for any free port)");
    port_ = options_.port;
  }
  if (options_.socket) {
    SocketOptions so;
    so.host = options_.host;
    so.port = options_.socket_port;
    so.http_port = port_;
    so.max_message = options_.max_body + 4096;  // the request line besides the body
    impl_->socket = std::make_unique<SocketServer>(api_, so);
    api_.set_socket_port(impl_->socket->bind());
  }
  return port_;
}

int Server::socket_port() const {
  return impl_->socket ? impl_->socket->port() : 0;
}

void Server::run() {
  if (impl_->socket) impl_->socket->start();
  impl_->http.listen_after_bind();
}

void Server::stop() {
  if (!impl_) return;
  impl_->http.stop();
  if (impl_->socket) impl_->socket->stop();
}

}  // namespace vitri::studio
