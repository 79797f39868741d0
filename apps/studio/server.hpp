#pragma once
// The studio's HTTP server (cpp-httplib): the API under /api/ and the page's files (our web/ folder and
// three.js from its installed location). Binds 127.0.0.1 unless told otherwise.
#include "api.hpp"

#include <cstddef>
#include <memory>
#include <string>

namespace vitri::studio {

struct ServerOptions {
  std::string host = "127.0.0.1";    ///< address to bind; another one exposes the studio to the network
  int port = 8080;                   ///< 0: any free port (see Server::port())
  std::string web_dir;               ///< folder with index.html, studio.js, studio.css
  std::string three_dir;             ///< three.js installation (build/three.min.js, examples/js/controls/)
  std::size_t max_body = 64u << 20;  ///< largest request body (an uploaded file); larger gets 413
};

/// The files the server serves besides the API: URL path -> file on disk (never a client-given path).
struct StaticFile {
  std::string url;
  std::string path;
  std::string content_type;
};
std::vector<StaticFile> static_files(const ServerOptions& options);

class Server {
 public:
  Server(Api& api, const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  /// Binds the address. @return the port. @throws vitri::Error when it cannot bind.
  int bind();
  /// Serves until stop() (from another thread or a signal-waiting thread). @pre bind() succeeded.
  void run();
  void stop();
  int port() const { return port_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ServerOptions options_;
  int port_ = 0;
};

}  // namespace vitri::studio
